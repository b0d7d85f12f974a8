"""This machine's ceilings (:func:`vrlib.roofline.measure`) on one thread and on all, for
the cost tables to state each ray-casting rate as a fraction of its ceiling.

Writes ``build/results/ch04_cost/roofline.json``.
"""

import numba

from chapters.common import result_path, write_json
from vrlib import roofline
from vrlib.cost import machine


def main():
    threads = sorted({1, numba.config.NUMBA_NUM_THREADS})
    write_json(result_path(__file__, "roofline.json"), {
        "machine": machine(), "brick": roofline.BRICK, "steps": roofline.STEPS,
        "limits": {str(t): roofline.measure(threads=t) for t in threads}})


if __name__ == "__main__":
    main()
