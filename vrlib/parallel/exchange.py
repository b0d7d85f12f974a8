"""The rounds of a sort-last exchange over MPI, and a failure in one of them ending every rank.

Every compositor of :mod:`vrlib.parallel.composite` is a sequence of rounds; in each, a rank
sends rectangles of pixels to some ranks and receives rectangles from others
(:meth:`Exchange.swap`). A rectangle travels as a header (its four pixel bounds) followed by
its pixels, so the receiver needs to know only who sends to it, not how much.

All sends and receives are non-blocking, and every wait also watches for a *failure notice*:
a rank that raises inside an exchange sends one to every other rank before its error leaves
:class:`Exchange`, and a rank waiting for pixels that will never come raises
:class:`~vrlib.parallel.stage.RankFailed` naming the rank that failed, instead of hanging.
The rounds run on a duplicate of the caller's communicator, so their messages never meet the
caller's own.
"""

from __future__ import annotations

import numpy as np
from mpi4py import MPI

from vrlib.parallel.rects import is_empty, pixels
from vrlib.parallel.stage import RankFailed, Stage

__all__ = ["Exchange", "HEADER"]

#: Header bytes counted for each rectangle sent (four int64 pixel bounds).
HEADER = 32
#: Tag of a failure notice; a round's headers and pixels take the tags above it.
_FAILED = 100
#: Bytes of a failure notice (the message is cut to fit).
_NOTICE = 2048
_NOTICES = []


class Exchange(Stage):
    """A context for one frame's compositing rounds on ``comm``: a
    :class:`~vrlib.parallel.stage.Stage` whose waits also end when another rank fails.

    Parameters
    ----------
    comm : mpi4py.MPI.Comm
    name : str
        The compositor's name, quoted in failure messages.
    sent : dict
        ``sent["composite"]`` counts the bytes this rank sends (headers and pixels).
    log : list, optional
        Receives one ``[round, destination, pixels]`` per rectangle sent.

    Examples
    --------
    On one rank nothing travels:

    >>> sent = {"composite": 0}
    >>> with Exchange(MPI.COMM_SELF, "demo", sent) as ex:
    ...     ex.swap(0, [], [])
    []
    >>> sent["composite"]
    0
    """

    def __init__(self, comm, name, sent, log=None):
        super().__init__(comm, f"compositing by {name}")
        self.compositor, self.sent, self.log = name, sent, log
        self.rank, self.size = comm.Get_rank(), comm.Get_size()
        self.round = None
        self.rounds = None

    def __enter__(self):
        self.rounds = self.comm.Dup()
        self._notice = bytearray(_NOTICE)
        self._watch = self.rounds.Irecv([self._notice, MPI.BYTE], source=MPI.ANY_SOURCE,
                                      tag=_FAILED)
        self._outgoing = []
        return self

    def __exit__(self, kind, value, traceback):
        if value is None:
            self._watch.Cancel()
            self._watch.Wait()
            self.rounds.Free()
        elif isinstance(value, Exception) and not isinstance(value, RankFailed):
            self.name = self.stage
            if self.size > 1:
                self._tell_everyone(f"{kind.__name__}: {value}")
        return super().__exit__(kind, value, traceback)

    @property
    def stage(self):
        """What this rank is doing, for failure messages."""
        where = "" if self.round is None else f" (round {self.round})"
        return f"compositing by {self.compositor}{where}"

    def _tell_everyone(self, message):
        """A failure notice to every other rank (sent eagerly; never waited for)."""
        text = f"{self.stage}\n{message}".encode()[:_NOTICE]
        for dest in range(self.size):
            if dest != self.rank:
                # Kept alive until the process ends: the job is ending anyway.
                _NOTICES.append((text, self.rounds.Isend([text, MPI.BYTE], dest=dest,
                                                          tag=_FAILED)))

    def _wait(self, requests, on_done=None):
        """Wait for every request; ``on_done(i)`` may return new requests to wait for too.
        Raises RankFailed when a failure notice arrives first."""
        pending = list(enumerate(requests))
        status = MPI.Status()
        while pending:
            index = MPI.Request.Waitany([self._watch] + [r for _, r in pending], status)
            if index == 0:
                stage, _, message = bytes(self._notice).rstrip(b"\0").decode(
                    errors="replace").partition("\n")
                raise RankFailed(status.Get_source(), stage, message)
            key, _ = pending.pop(index - 1)
            if on_done is not None:
                pending += on_done(key)

    def swap(self, round, sends, receives):
        """One round: send each ``(destination, rect, rgba)`` of ``sends`` (the pixels of
        ``rgba`` in ``rect``; an empty rect sends its header only) and receive one rectangle
        per entry of ``receives`` (source ranks, in the order each source sends).

        Returns ``[(rect, pixels), ...]`` in the order of ``receives`` (pixels None for an
        empty rect).
        """
        self.round = round
        head_tag, pixel_tag = _FAILED + 1 + 2 * round, _FAILED + 2 + 2 * round
        requests = []
        for dest, rect, rgba in sends:
            header = np.asarray(rect, dtype=np.int64)
            self._outgoing.append(header)
            requests.append(self.rounds.Isend(header, dest=dest, tag=head_tag))
            self.sent["composite"] += HEADER
            count = 0
            if not is_empty(rect):
                buf = pixels(rgba, rect)
                self._outgoing.append(buf)
                requests.append(self.rounds.Isend(buf, dest=dest, tag=pixel_tag))
                self.sent["composite"] += buf.nbytes
                count = buf.shape[0] * buf.shape[1]
            if self.log is not None:
                self.log.append([round, int(dest), int(count)])
        headers = [np.empty(4, dtype=np.int64) for _ in receives]
        received = [None] * len(receives)
        # Keys: ("h", i) a header, ("p", i) pixels, ("s", j) a send.
        keys = [("s", j) for j in range(len(requests))]
        waits = list(requests)
        for i, source in enumerate(receives):
            keys.append(("h", i))
            waits.append(self.rounds.Irecv(headers[i], source=source, tag=head_tag))

        def arrived(position):
            kind, i = keys[position]
            if kind != "h":
                return []
            rect = tuple(int(v) for v in headers[i])
            if is_empty(rect):
                received[i] = (rect, None)
                return []
            buf = np.empty((rect[1] - rect[0], rect[3] - rect[2], 4))
            received[i] = (rect, buf)
            keys.append(("p", i))
            return [(len(keys) - 1, self.rounds.Irecv(buf, source=receives[i],
                                                    tag=pixel_tag))]

        self._wait(waits, arrived)
        self._outgoing.clear()
        return received
