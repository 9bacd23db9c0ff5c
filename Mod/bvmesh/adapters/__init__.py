"""Conversions between FreeCAD objects and what the core takes: BREP text and numpy arrays."""
