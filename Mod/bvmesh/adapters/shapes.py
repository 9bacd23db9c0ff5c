"""FreeCAD Part shapes <-> BREP text, the form in which shapes cross into the core."""

import os

import FreeCAD  # noqa: F401  -- must be loaded before Part, or Part crashes plain python
import Part


def shape_to_brep(shape):
    """BREP text of a Part.Shape; ValueError for a null shape or a non-shape."""
    if not isinstance(shape, Part.Shape):
        raise ValueError("expected a Part.Shape, got {}".format(type(shape).__name__))
    if shape.isNull():
        raise ValueError("the shape is null (empty)")
    return shape.exportBrepToString()


def brep_to_shape(brep):
    """Part.Shape from BREP text written by the core."""
    shape = Part.Shape()
    shape.importBrepFromString(brep)
    if shape.isNull():
        raise ValueError("the core returned BREP text that FreeCAD reads as a null shape")
    return shape


def read_shape_file(path):
    """Part.Shape from a STEP / IGES / BREP file, read by the core (one reader for every caller)."""
    from bvmesh import load_core

    return brep_to_shape(load_core().read_cad_file_as_brep(os.fspath(path)))


def as_shape(shape_or_object):
    """The Part.Shape of a shape, a document object with a Shape, or a file path."""
    if isinstance(shape_or_object, (str, os.PathLike)):
        return read_shape_file(shape_or_object)
    shape = getattr(shape_or_object, "Shape", shape_or_object)
    if not isinstance(shape, Part.Shape):
        raise ValueError(
            "expected a Part.Shape, an object with a Shape or a CAD file path, got {}".format(
                type(shape_or_object).__name__
            )
        )
    return shape
