"""The peer renderers of ``benchmarks/`` (VTK's CPU ray caster through pyvista, VolPack through
ctypes), imported from there so that the chapter and the benchmarks time the same set-up."""

import sys

from chapters.common import ROOT


def peers():
    """``(VTKCaster or None, (load, VolPack))``: VTK is None when pyvista is missing."""
    sys.path.insert(0, str(ROOT / "benchmarks"))
    from _volpack import VolPack, load

    try:
        from bench_raycast_vtk import VTKCaster
    except ImportError:
        VTKCaster = None
    return VTKCaster, (load, VolPack)
