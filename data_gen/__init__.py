"""Synthetic analytic volumes and loaders for real ones.

>>> import data_gen
>>> field = data_gen.make_field("gaussian-blob", sigma=0.3, amplitude=1.0)
>>> field.sample(16).shape
(16, 16, 16)
"""

from data_gen.datasets import DATASETS, load_dataset, load_mni_template
from data_gen.fields import (
    BlobSum,
    Field,
    GaussianBlob,
    Grating,
    MarschnerLobb,
    SmoothSphere,
    StepEdge,
)
from data_gen.loaders import (
    FORMATS,
    fitted_extent,
    load,
    load_den,
    load_dicom,
    load_nifti,
    load_npy,
    load_nrrd,
    load_raw,
    load_tiff,
    load_vtk,
)
from vrlib import validate

#: Field constructors by name.
FIELDS = {
    "gaussian-blob": GaussianBlob,
    "blobs": BlobSum,
    "random-blobs": BlobSum.random,
    "marschner-lobb": MarschnerLobb,
    "smooth-sphere": SmoothSphere,
    "grating": Grating,
    "step-edge": StepEdge,
}


def make_field(name, **params):
    """Build an analytic field by name with its parameters.

    Raises
    ------
    ValueError
        An unknown name (the message lists the known ones) or a bad parameter value.
    TypeError
        A parameter the field does not take.

    Examples
    --------
    >>> make_field("marschner-lobb", fM=6)
    make_field('marschner-lobb', fM=6.0, alpha=0.25)
    >>> make_field("sphere")
    Traceback (most recent call last):
    ...
    ValueError: unknown field 'sphere'; known: 'gaussian-blob', 'blobs', 'random-blobs', \
'marschner-lobb', 'smooth-sphere', 'grating', 'step-edge'
    """
    validate.choice("field", name, tuple(FIELDS))
    try:
        return FIELDS[name](**params)
    except (TypeError, ValueError) as exc:
        raise type(exc)(f"bad parameters for field {name!r}: {exc}") from None


__all__ = [
    "FIELDS",
    "make_field",
    "Field",
    "GaussianBlob",
    "BlobSum",
    "MarschnerLobb",
    "SmoothSphere",
    "Grating",
    "StepEdge",
    "load",
    "load_npy",
    "load_nifti",
    "load_raw",
    "load_nrrd",
    "load_tiff",
    "load_vtk",
    "load_dicom",
    "load_den",
    "FORMATS",
    "DATASETS",
    "load_dataset",
    "load_mni_template",
    "fitted_extent",
]
