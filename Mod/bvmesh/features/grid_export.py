"""Export of a volume grid (or of the B-spline blocks themselves) to the files solvers read:
CGNS, an OpenFOAM case's polyMesh or a complete OpenFOAM flow case, Plot3D, VTK, G+Smo XML, or
BVMesh's block file. Recompute
writes the file (each writer writes a temporary file and renames it, so a failed export leaves no
partial file under the name)."""

import os

from bvmesh.features import volume_grid, volume_mesh
from bvmesh.features.common import READ_ONLY, Proxy, add_property, is_type

TYPE = "BVMesh::Export"
# format -> (file name endings that select it, needs the grid (else the blocks))
FORMATS = {
    "cgns": ((".cgns",), True),
    "openfoam": ((), True),  # a case directory: constant/polyMesh
    "openfoam_case": ((), True),  # a complete flow case (bvmesh.openfoam_case; chosen by name only)
    "plot3d": ((".xyz", ".p3d", ".x"), True),
    "vtk": ((".vtm",), True),
    "gismo": ((".xml",), False),
    "blocks": ((".blocks", ".txt"), False),
}


def format_of_path(path):
    """The format a path's ending names; a path without one of them is an OpenFOAM case directory."""
    ending = os.path.splitext(os.fspath(path))[1].lower()
    for name, (endings, _) in FORMATS.items():
        if ending in endings:
            return name
    if ending:
        raise ValueError("no export format for '{}' files; known: .cgns, .xyz/.p3d/.x (Plot3D), .vtm (VTK), "
                         ".xml (G+Smo), .blocks (block file), or a directory for an OpenFOAM case".format(ending))
    return "openfoam"


def write(source, file_format, path, force=False):
    """Writes a VolumeGrid (or, for gismo / blocks, a VolumeMesh or the mesh of a VolumeGrid)."""
    from bvmesh import grid

    if file_format not in FORMATS:
        raise ValueError("export format must be one of {}, got {!r}".format(", ".join(FORMATS), file_format))
    path = os.fspath(path)
    if not path:
        raise ValueError("the export needs a path")
    if FORMATS[file_format][1]:
        if not is_type(source, volume_grid.TYPE):
            raise ValueError("{} export needs a volume grid, got {}".format(file_format, source.Label))
        refined = volume_grid.refined_grid(source)
        if file_format == "openfoam_case":
            from bvmesh import openfoam_case

            # Free stream and references are openfoam_case's defaults (the M6's wind-tunnel case);
            # scripts set them with bvmesh.api.write_openfoam_case.
            openfoam_case.write_case(refined, path, model="rans" if source.Preset == "rans" else "euler",
                                     reynolds_number=source.VolumeMesh.ReynoldsNumber if source.Preset == "rans" else None,
                                     force=force)
            return
        writers = {"cgns": grid.write_cgns, "openfoam": grid.write_openfoam, "plot3d": grid.write_plot3d,
                   "vtk": grid.write_vtk}
        writers[file_format](refined, path, force=force)
        return
    mesh_object = source.VolumeMesh if is_type(source, volume_grid.TYPE) else source
    if not is_type(mesh_object, volume_mesh.TYPE):
        raise ValueError("{} export needs a volume mesh or grid, got {}".format(file_format, source.Label))
    blocks = volume_mesh.volume_mesh(mesh_object).blocks
    if file_format == "gismo":
        grid.write_gismo(blocks, path)
    else:
        blocks.write(path)


class ExportProxy(Proxy):
    Type = TYPE

    def setup(self, obj):
        add_property(obj, "App::PropertyLink", "Source", "Export", "The volume grid (or volume mesh) to write")
        if "Format" not in obj.PropertiesList:
            obj.addProperty("App::PropertyEnumeration", "Format", "Export", "File format")
            obj.Format = list(FORMATS)
            obj.Format = "cgns"
        add_property(obj, "App::PropertyString", "Path", "Export",
                     "File (or OpenFOAM case directory) written on recompute")
        add_property(obj, "App::PropertyBool", "Force", "Export",
                     "Write even a grid with non-positive cells (refused otherwise)", False)
        add_property(obj, "App::PropertyString", "Written", "Result", "Digest of the grid last written",
                     mode=READ_ONLY)

    def compute(self, obj):
        if obj.Source is None:
            raise ValueError("the export needs a source")
        write(obj.Source, obj.Format, obj.Path, obj.Force)
        obj.Written = obj.Source.Digest


def create(doc, name="Export"):
    obj = doc.addObject("App::FeaturePython", name)
    ExportProxy(obj)
    return obj
