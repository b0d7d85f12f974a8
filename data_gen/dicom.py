"""Writing a volume as a DICOM series (one CT slice file per z plane) or as one multi-frame
file (an enhanced CT image), for tests and for users who need DICOM to try a pipeline on.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

__all__ = ["write_series", "write_multiframe"]


#: Rows along RAS +x and columns along RAS +y, in DICOM's patient coordinates (LPS).
_RAS_AXES_IN_LPS = [-1, 0, 0, 0, -1, 0]


def _lps(origin, depth):
    """The RAS point ``origin`` raised by ``depth`` along z, in patient coordinates (LPS)."""
    return [-float(origin[0]), -float(origin[1]), float(origin[2] + depth)]


def _ct_dataset(sop_class, study, series, shape):
    """A CT dataset of ``sop_class`` with its file meta, study and series, and 16-bit signed
    monochrome pixels of ``shape`` (rows, columns), its pixel data still to set."""
    from pydicom.dataset import Dataset, FileMetaDataset
    from pydicom.uid import ExplicitVRLittleEndian, generate_uid

    meta = FileMetaDataset()
    meta.MediaStorageSOPClassUID = sop_class
    meta.MediaStorageSOPInstanceUID = generate_uid()
    meta.TransferSyntaxUID = ExplicitVRLittleEndian
    ds = Dataset()
    ds.file_meta = meta
    ds.SOPClassUID, ds.SOPInstanceUID = sop_class, meta.MediaStorageSOPInstanceUID
    ds.Modality, ds.StudyInstanceUID, ds.SeriesInstanceUID = "CT", study, series
    ds.Rows, ds.Columns = shape
    ds.SamplesPerPixel, ds.PhotometricInterpretation = 1, "MONOCHROME2"
    ds.BitsAllocated, ds.BitsStored, ds.HighBit, ds.PixelRepresentation = 16, 16, 15, 1
    return ds


def write_series(folder, data, *, spacing=(1.0, 1.0, 1.0), origin=(0.0, 0.0, 0.0),
                 slope=1.0, intercept=0.0, series_uid=None, shuffle=False, prefix="slice"):
    """Write ``data[z, y, x]`` (integers) as one uncompressed DICOM CT slice per z plane,
    its RAS geometry written in DICOM's patient coordinates (LPS).

    Stored values are ``(data - intercept) / slope`` as 16-bit integers, so a loader that
    applies ``RescaleSlope`` and ``RescaleIntercept`` gets ``data`` back.

    Parameters
    ----------
    folder : path
        Created if missing; slices are named ``{prefix}_NNNN.dcm``.
    spacing, origin : 3 floats
        Voxel size and position of the first sample (x, y, z), in mm.
    series_uid : str, optional
        The series' ``SeriesInstanceUID`` (default: a new one).
    shuffle : bool
        Name the files in an order other than their positions (as scanners often do).
    prefix : str, default "slice"
        Start of the file names (two series in one folder need two prefixes).

    Examples
    --------
    >>> import tempfile
    >>> files = write_series(tempfile.mkdtemp(), np.zeros((2, 3, 4), np.int16))
    >>> len(files), files[0].name
    (2, 'slice_0000.dcm')
    """
    from pydicom.uid import CTImageStorage, generate_uid

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    values = np.rint((np.asarray(data, dtype=np.float64) - intercept) / slope)
    if values.min() < -32768 or values.max() > 32767:
        raise ValueError("data do not fit 16-bit slices at this slope and intercept")
    values = values.astype(np.int16)
    series_uid = series_uid or generate_uid()
    study = generate_uid()
    nz = values.shape[0]
    names = np.random.default_rng(0).permutation(nz) if shuffle else np.arange(nz)
    files = []
    for z in range(nz):
        ds = _ct_dataset(CTImageStorage, study, series_uid, values.shape[1:])
        ds.InstanceNumber = z + 1
        ds.ImageOrientationPatient = _RAS_AXES_IN_LPS
        ds.ImagePositionPatient = _lps(origin, z * spacing[2])
        ds.PixelSpacing = [float(spacing[1]), float(spacing[0])]  # rows (y), columns (x)
        ds.SliceThickness = float(spacing[2])
        ds.RescaleSlope, ds.RescaleIntercept = float(slope), float(intercept)
        ds.PixelData = values[z].tobytes()
        path = folder / f"{prefix}_{int(names[z]):04d}.dcm"
        ds.save_as(path, enforce_file_format=True)
        files.append(path)
    return files


def write_multiframe(path, data, *, spacing=(1.0, 1.0, 1.0), origin=(0.0, 0.0, 0.0),
                     slope=1.0, intercept=0.0, reverse=False):
    """Write ``data[z, y, x]`` (integers) as one enhanced CT file, a frame per z plane, its
    geometry and rescale in the functional groups (``reverse`` stores the frames from the
    last plane to the first, as some scanners do). Returns the path.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> write_multiframe(pathlib.Path(tempfile.mkdtemp()) / "v.dcm",
    ...                  np.zeros((2, 3, 4), np.int16)).name
    'v.dcm'
    """
    from pydicom.dataset import Dataset
    from pydicom.sequence import Sequence
    from pydicom.uid import EnhancedCTImageStorage, generate_uid

    path = Path(path)
    values = np.rint((np.asarray(data, dtype=np.float64) - intercept) / slope).astype(np.int16)
    order = range(values.shape[0] - 1, -1, -1) if reverse else range(values.shape[0])
    ds = _ct_dataset(EnhancedCTImageStorage, generate_uid(), generate_uid(), values.shape[1:])
    ds.NumberOfFrames = values.shape[0]
    measures, orientation, transform = Dataset(), Dataset(), Dataset()
    measures.PixelSpacing = [float(spacing[1]), float(spacing[0])]
    measures.SliceThickness = float(spacing[2])
    orientation.ImageOrientationPatient = _RAS_AXES_IN_LPS
    transform.RescaleSlope, transform.RescaleIntercept = float(slope), float(intercept)
    shared = Dataset()
    shared.PixelMeasuresSequence = Sequence([measures])
    shared.PlaneOrientationSequence = Sequence([orientation])
    shared.PixelValueTransformationSequence = Sequence([transform])
    ds.SharedFunctionalGroupsSequence = Sequence([shared])
    frames = []
    for z in order:
        position, group = Dataset(), Dataset()
        position.ImagePositionPatient = _lps(origin, z * spacing[2])
        group.PlanePositionSequence = Sequence([position])
        frames.append(group)
    ds.PerFrameFunctionalGroupsSequence = Sequence(frames)
    ds.PixelData = np.ascontiguousarray(values[list(order)]).tobytes()
    ds.save_as(path, enforce_file_format=True)
    return path
