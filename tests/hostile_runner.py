"""Run command lines of ``vrlib`` on hostile files, each in a forked child under an address
space limit and a time limit: ``python hostile_runner.py CASES.json RESULTS.json``.

Each case is ``{"id": ..., "argv": [...]}``; each result records the exit status, what the
command wrote to stderr, the seconds it took, and how far it raised the child's peak
resident memory above the parent's (MB). A case that runs past :data:`SECONDS` reports exit
status ``"timeout"``, one that exhausts the address space ``"memory"``, one that raises
``"raised ..."``, one that the system kills (VTK aborts on a grid it cannot allocate)
``"signal N"``: a crash fails its own case only. A child still running :data:`SECONDS` + 5 s
after it started (stuck in C code, where its alarm cannot stop it) is killed, so no case
outlives the run.
"""

import contextlib
import io
import json
import os
import resource
import select
import signal
import sys
import time

#: The address space a case may take (bytes): the imports take about 2 GB of it on this
#: machine's Python; a file that made vrlib allocate gigabytes would hit it.
ADDRESS_SPACE = 3 * 1024**3
#: Seconds one case may run.
SECONDS = 30


class _Timeout(BaseException):  # not caught by the code under test's "except Exception"
    pass


def _alarm(signum, frame):
    raise _Timeout


def _run(case, err):
    import vrlib.cli

    resource.setrlimit(resource.RLIMIT_AS, (ADDRESS_SPACE, ADDRESS_SPACE))
    signal.signal(signal.SIGALRM, _alarm)
    signal.alarm(SECONDS)
    try:
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
            return vrlib.cli.main(case["argv"])
    except _Timeout:
        return "timeout"
    except MemoryError:
        return "memory"
    except BaseException as error:  # noqa: BLE001 - a traceback is what the test looks for
        return f"raised {type(error).__name__}: {error}"
    finally:
        signal.alarm(0)


def _read_until(fd, deadline):
    """All a child writes to ``fd`` until it closes it, or None if the deadline (a
    ``time.perf_counter`` value) passes first."""
    chunks = []
    try:
        while True:
            left = deadline - time.perf_counter()
            if left <= 0 or not select.select([fd], [], [], left)[0]:
                return None
            chunk = os.read(fd, 65536)
            if not chunk:
                return b"".join(chunks).decode()
            chunks.append(chunk)
    finally:
        os.close(fd)


#: The readers' libraries, which vrlib imports when a file of their format is first read:
#: imported once here, before the children fork (each child importing its own took a
#: NIfTI or VTK case 0.2-0.3 s where the refusal itself takes 0.01).
READERS = ("nibabel", "pyvista", "tifffile", "pydicom", "data_gen.nrrd_files")


def main(cases_path, results_path):
    import importlib

    import vrlib.cli  # noqa: F401 - imported once, before the children fork

    for name in READERS:
        importlib.import_module(name)

    with open(cases_path) as fh:
        cases = json.load(fh)
    base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    results = {}
    for case in cases:
        read, write = os.pipe()
        start = time.perf_counter()
        pid = os.fork()
        if pid == 0:  # the child: run the case, send its outcome, leave at once
            os.close(read)
            err = io.StringIO()
            status = _run(case, err)
            peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
            with os.fdopen(write, "w") as out:
                json.dump({"status": status, "stderr": err.getvalue(),
                           "peak_growth_mb": (peak - base) / 1024}, out)
            os._exit(0)
        os.close(write)
        text = _read_until(read, start + SECONDS + 5)
        if text is None:  # stuck where its alarm cannot reach it (in C): kill it
            os.kill(pid, signal.SIGKILL)
        _, wait_status = os.waitpid(pid, 0)
        if text is None:
            result = {"status": "timeout", "stderr": "", "peak_growth_mb": 0.0}
        elif os.WIFSIGNALED(wait_status):
            result = {"status": f"signal {os.WTERMSIG(wait_status)}", "stderr": "",
                      "peak_growth_mb": 0.0}
        else:
            result = json.loads(text)
        result["seconds"] = time.perf_counter() - start
        results[case["id"]] = result
    with open(results_path, "w") as fh:
        json.dump(results, fh)


if __name__ == "__main__":
    main(*sys.argv[1:])
