"""Real volumes that ship inside installed packages, loadable by name (no download).

========== ================================================ ==========================
name       what it is                                        where it comes from
========== ================================================ ==========================
mni152     MNI152 T1 brain template, 2 mm (99x117x95)        nilearn (``vrlib[mri]``)
frog       frog tissue labels, 500x470x136, 0..29            pyvista's examples
aniso      anisotropic-voxel brain MRI (dipy test data)      dipy (``vrlib[data]``)
brainsmall VolPack's MRI head example, 128x128x84, 8 bit     Debian's libvolpack1-dev
========== ================================================ ==========================

Licences, as their packages state them: the MNI152 template (ICBM 2009c, McConnell Brain
Imaging Centre) may be used, copied and distributed with its copyright notice kept, as
nilearn ships it; pyvista's example data comes with pyvista under the MIT licence (the frog
tissues are the segmentation of the Whole Frog Project's frog, as VTK's examples use it);
dipy's data files are BSD-3-Clause with dipy; VolPack and its example head are BSD-3-Clause
(Debian's ``copyright`` file for libvolpack1: Stanford's licence since 2007).
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

__all__ = ["DATASETS", "load_dataset", "dataset_path", "load_mni_template"]

#: Named real volumes: a one-line description and the package that ships each.
DATASETS = {
    "mni152": "MNI152 T1 brain template, 2 mm voxels (nilearn)",
    "frog": "frog tissue labels 0..29 on a 500x470x136 grid (pyvista examples)",
    "aniso": "brain MRI with anisotropic voxels, 58x58x24, oblique: shown in its voxel axes "
             "(dipy test data)",
    "brainsmall": "VolPack's example MRI head, 128x128x84, 8 bit (Debian libvolpack1-dev)",
}

_VOLPACK_EXAMPLES = Path("/usr/share/doc/libvolpack1-dev/examples")


def _package_file(package, *parts, install):
    spec = importlib.util.find_spec(package)
    if spec is None or spec.origin is None:
        raise ImportError(f"this volume ships inside {package}: install it with {install}")
    path = Path(spec.origin).parent.joinpath(*parts)
    if not path.is_file():
        raise FileNotFoundError(f"{package} is installed but lacks {'/'.join(parts)}")
    return path


def dataset_path(name):
    """The file a named volume is read from (mni152 has none: nilearn builds it).

    Raises
    ------
    ImportError
        The package that ships it is missing (the message says how to install it).

    Examples
    --------
    >>> dataset_path("frog").name
    'frog_tissues.vti'
    """
    if name == "frog":
        return _package_file("pyvista", "examples", "frog_tissues.vti",
                             install="pip install 'vrlib[vtk]'")
    if name == "aniso":
        return _package_file("dipy", "data", "files", "aniso_vox.nii.gz",
                             install="pip install 'vrlib[data]'")
    if name == "brainsmall":
        path = _VOLPACK_EXAMPLES / "brainsmall.den"
        if not path.is_file():
            raise ImportError("brainsmall ships with VolPack's examples: install Debian's "
                              "libvolpack1-dev (apt-get install libvolpack1-dev)")
        return path
    raise ValueError(f"no file for volume {name!r}; files exist for frog, aniso, brainsmall")


def load_mni_template(*, resolution=2, nan="error"):
    """The MNI152 T1 template bundled inside nilearn (no download): a real MRI volume in mm.

    Raises
    ------
    ImportError
        If nilearn is not installed (``pip install 'vrlib[mri]'``).

    Examples
    --------
    >>> vol = load_mni_template()
    >>> vol.shape, vol.spacing.tolist()        # [z, y, x] at 2 mm
    ((95, 117, 99), [2.0, 2.0, 2.0])
    """
    from data_gen.loaders import nifti_volume

    try:
        from nilearn.datasets import load_mni152_template
    except ImportError as exc:
        raise ImportError(
            "the MRI template ships inside nilearn: install it with pip install 'vrlib[mri]'"
        ) from exc
    if resolution not in (1, 2):
        raise ValueError(f"resolution must be 1 or 2 (mm), got {resolution!r}")
    return nifti_volume(load_mni152_template(resolution=resolution), "MNI152 template",
                        nan=nan)


def load_dataset(name, **options):
    """Load a named real volume (:data:`DATASETS`) in its own units (mm, or voxels for the
    frog and brainsmall).

    Examples
    --------
    >>> vol = load_dataset("frog")
    >>> vol.shape, vol.value_range
    ((136, 470, 500), (0.0, 29.0))
    """
    from data_gen.loaders import load_den, load_nifti, load_vtk

    if name not in DATASETS:
        raise ValueError(f"unknown volume {name!r}; named volumes: {', '.join(DATASETS)}")
    if name == "mni152":
        return load_mni_template(**options)
    path = dataset_path(name)
    if name == "aniso":  # an oblique scan, shown in its own voxel axes
        return load_nifti(path, **{"oblique": "voxel-axes", **options})
    loader = {"frog": load_vtk, "brainsmall": load_den}[name]
    return loader(path, **options)
