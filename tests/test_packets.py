"""The ray caster's packets (:func:`vrlib._kernels.packets.inside_runs`): eight rays' runs in
vector form do, lane by lane, what the scalar loop does (the renders that use them are checked
against their naive twins in ``test_raycast.py``)."""

import numba
import numpy as np
import pytest

from vrlib._kernels import packets
from vrlib._kernels.packets import ALPHA, AX, BX, END, LANES, RAY_ROWS, RED, K


def lanes_in_a_volume(rng, shape, groups, shift=0):
    """``groups`` packets of rays that start inside a volume of ``shape`` and run to where
    they leave its cells (each lane's ``end``), a few lanes idle (``end = k``) or starting
    part-composited."""
    gz, gy, gx = shape
    rays = np.zeros((groups, RAY_ROWS, LANES))
    steps = np.zeros((groups, 2, LANES), np.int64)
    ds = 0.7
    for g in range(groups):
        for lane in range(LANES):
            a = rng.uniform(0.5, np.array([gx, gy, gz]) - 1.5)
            b = rng.normal(size=3)
            b /= np.linalg.norm(b)
            rays[g, AX:AX + 3, lane] = a
            rays[g, BX:BX + 3, lane] = b
            # The samples whose cells lie inside: positions in [0, n - 1) on every axis.
            k = 0
            while True:
                u = a + (k + 0.5) * ds * b
                if not np.all((u >= 0.0) & (u < np.array([gx, gy, gz]) - 1.0)):
                    break
                k += 1
            steps[g, END, lane] = k if rng.random() > 0.1 else 0
            rays[g, RED:ALPHA + 1, lane] = 0.5 if rng.random() < 0.2 else 0.0
    rays[:, AX:AX + 3] += np.array([0.0, 0.0, shift])[:, None]
    return rays, steps, ds


@pytest.mark.skipif(numba.config.DISABLE_JIT, reason="the vector form exists compiled only")
@pytest.mark.parametrize("dtype", [np.float32, np.float64])
@pytest.mark.parametrize("grey", [True, False], ids=["grey", "colour"])
@pytest.mark.parametrize("threshold", [1.0, 0.9], ids=["no-termination", "termination"])
def test_packet_runs_equal_the_scalar_loop_lane_by_lane(dtype, grey, threshold):
    """Compiled, the runs of a packet (gathers, lane masks, early termination per lane) give
    each lane's opacity, colour and end sample bit for bit as the scalar loop of
    ``_inside_runs_lanes`` (the same loop without the JIT), in a brick whose samples start
    past global index 0 along z. A lane that read a neighbour's corner, took one sample
    too many after it turned opaque, or widened a float32 difference too early would
    differ."""
    rng = np.random.default_rng(7)
    shape, shift = (14, 12, 13), 3
    data = rng.uniform(0.0, 1.0, shape).astype(dtype)
    flat = data.reshape(-1)
    nx, nxy = shape[2], shape[1] * shape[2]
    alpha_tab = np.linspace(0.0, 0.35, 64)
    alpha_tab[:10] = 0.0  # transparent values: segments that add nothing
    color_tab = rng.uniform(0.0, 1.0, (64, 3)) * alpha_tab[:, None]
    rays, steps, ds = lanes_in_a_volume(rng, shape, groups=12, shift=shift)
    expected_rays, expected_steps = rays.copy(), steps.copy()
    compiled = packets._inside_runs_compiled
    colour = None if grey else True  # None: the colour is the opacity
    for g in range(len(rays)):
        compiled(flat, nx, nxy, shift * nxy, alpha_tab, color_tab, colour, ds, -0.05, 60.0,
                 threshold, rays[g], steps[g])
        packets._inside_runs_lanes(flat, nx, nxy, shift * nxy, alpha_tab, color_tab, colour,
                                   ds, -0.05, 60.0, threshold, expected_rays[g],
                                   expected_steps[g])
    np.testing.assert_array_equal(steps, expected_steps)
    np.testing.assert_array_equal(rays, expected_rays)
    taken = steps[:, K] > 0
    assert taken.mean() > 0.6  # most lanes take samples
    if threshold < 1.0:
        stopped = rays[:, ALPHA] >= threshold
        assert stopped.any() and (steps[:, K][stopped] < steps[:, END][stopped]).any()
