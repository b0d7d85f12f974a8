"""Compositing at scale: direct send, binary swap and radix-k with every ``k``, simulated round
by round on 2-D meshes and tori of up to 4096 nodes, and the best ``k`` for each node count.

One frame: a ``WIDTH^2`` image of a ``SAMPLES^3`` volume, one brick per node cut by each
compositor's own k-d tree (:meth:`vrlib.parallel.composite.Compositor.split`), each message the
part of a region inside what the sender holds (:mod:`vrlib.parallel.composite`'s ``rounds``,
the schedule the MPI renderer runs). Each round's messages are routed with dimension-order
routing (:mod:`vrlib.parallel.network`). A round costs
``ALPHA x (messages the busiest sender sends) + (bytes on the busiest channel, or sent by the
busiest node if more) / BETA``, and a frame the sum of its rounds: latency for every message a
node must post, bandwidth for the most loaded link or interface. ``ALPHA`` and ``BETA`` are
stated assumptions (a current cluster interconnect), not measurements; the counts beside them
(rounds, messages, bytes, busiest channel) are exact. Writes
``build/results/ch06_parallel/compositing.json``.
"""

import numpy as np

from chapters.common import by_profile, progress, result_path, write_json
from vrlib import View
from vrlib.parallel import network
from vrlib.parallel.composite import COMPOSITORS, RadixK, radix_factors
from vrlib.parallel.decompose import screen_tiles

NODES = by_profile([4, 6, 8, 12, 16, 24, 32, 48, 64, 96, 128, 256, 384, 512, 1024, 2048, 4096],
                   [4, 6, 8, 12, 16, 24, 32, 48, 64, 96, 128, 256, 384, 512, 1024, 2048, 4096])
WIDTH = 2048
SAMPLES = 257
PIXEL_BYTES = 4        # 8-bit RGBA
ALPHA = 2e-6           # seconds per message posted (assumed)
BETA = 10e9            # bytes per second per channel and per node interface (assumed)
TARGETS = [2, 4, 8, 16, 32, 64, 128, 256]  # largest k of radix-k's factorisation
ORBIT = {"azimuth": 30.0, "elevation": 20.0}


def schedules(nodes):
    """The compositors compared at ``nodes`` nodes: (label, compositor, k target or None)."""
    out = [("direct send", COMPOSITORS["direct-send"], None),
           ("binary swap", COMPOSITORS["binary-swap"], None)]
    seen = set()
    for target in TARGETS:
        factors = tuple(radix_factors(nodes, target))
        if factors not in seen:
            seen.add(factors)
            out.append((f"radix-k {'x'.join(map(str, factors))}", RadixK(factors), target))
    return out


def simulate(compositor, nodes, view, nets):
    """Counts and the modelled time of one frame on each network."""
    origin, spacing = np.array([-1.0, -1.0, -1.0]), np.full(3, 2.0 / (SAMPLES - 1))
    tree = compositor.split((SAMPLES - 1,) * 3, nodes)
    tiles = screen_tiles(WIDTH, WIDTH, nodes) if compositor.name == "direct-send" else None
    rounds = compositor.rounds(tree, np.arange(nodes), tiles, view, origin, spacing,
                               bytes_per_pixel=PIXEL_BYTES)
    rounds = [m for m in rounds if m.bytes.size]
    sent = sum(m.sent_per_node(nodes) for m in rounds) if rounds else np.zeros(nodes)
    row = {"rounds": len(rounds), "total": float(sum(m.total for m in rounds)),
           "max_sent": float(sent.max()),
           "messages": int(max((np.bincount(m.src, minlength=nodes).max() for m in rounds),
                               default=0)),
           "messages_total": int(sum(m.bytes.size for m in rounds))}
    for kind, net in nets.items():
        seconds = busiest = 0.0
        for m in rounds:
            load = net.route(m.src, m.dst, m.bytes)
            count = np.bincount(m.src, minlength=nodes).max()
            heaviest = max(load.max, float(m.sent_per_node(nodes).max()))
            seconds += ALPHA * count + heaviest / BETA
            busiest += load.max
        row[kind] = {"seconds": seconds, "busiest": busiest}
    return row


def main():
    view = View.orbit(size=WIDTH, **ORBIT)
    rows = []
    for nodes in progress(NODES, "node counts"):
        nets = {"mesh": network.Network.square(nodes),
                "torus": network.Network.square(nodes, torus=True)}
        for label, compositor, target in schedules(nodes):
            row = simulate(compositor, nodes, view, nets)
            rows.append({"nodes": nodes, "label": label, "target": target,
                         "factors": (compositor.factors_for(nodes)
                                     if isinstance(compositor, RadixK) else None), **row})
    best = {}
    for kind in ("mesh", "torus"):
        for nodes in NODES:
            sel = [r for r in rows if r["nodes"] == nodes]
            radix = [r for r in sel if r["factors"] is not None]
            fastest = min(radix, key=lambda r: r[kind]["seconds"])
            swap = next(r for r in sel if r["label"] == "binary swap")
            direct = next(r for r in sel if r["label"] == "direct send")
            default = next(r for r in radix if r["target"] == 8 or
                           r["factors"] == radix_factors(nodes, 8))
            best.setdefault(kind, []).append({
                "nodes": nodes, "factors": fastest["factors"], "label": fastest["label"],
                "seconds": fastest[kind]["seconds"], "rounds": fastest["rounds"],
                "binary_swap_seconds": swap[kind]["seconds"],
                "direct_send_seconds": direct[kind]["seconds"],
                "default_seconds": default[kind]["seconds"],
                "speedup_over_binary_swap": swap[kind]["seconds"] / fastest[kind]["seconds"],
                "bytes_over_binary_swap": fastest["total"] / swap["total"]})
    write_json(result_path(__file__, "compositing.json"), {
        "width": WIDTH, "samples": SAMPLES, "pixel_bytes": PIXEL_BYTES, "alpha": ALPHA,
        "beta": BETA, "targets": TARGETS, "orbit": ORBIT, "nodes": NODES, "rows": rows,
        "best": best})


if __name__ == "__main__":
    main()
