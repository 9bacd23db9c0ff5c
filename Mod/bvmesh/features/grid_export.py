"""Export of a volume grid (or of the B-spline blocks themselves) to the files solvers read:
CGNS, an OpenFOAM case's polyMesh or a complete OpenFOAM flow case, Plot3D, VTK, G+Smo XML, or
BVMesh's block file. Recompute writes the file (each writer writes a temporary file and renames
it, so a failed export leaves no partial file under the name). A flow case takes its free stream,
solver and force references from the object's "Flow case" properties, shown for that format only."""

import os

from bvmesh import openfoam_case
from bvmesh.features import volume_grid, volume_mesh
from bvmesh.features.common import HIDDEN, READ_ONLY, Proxy, add_property, is_type

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
FLOW_CASE_GROUP = "Flow case"
METRES_PER_MM = 1e-3
# property -> (openfoam_case.write_case keyword, property type, default, tooltip). Defaults:
# openfoam_case's (the ONERA M6 wind-tunnel case), lengths in the document's millimetres.
FLOW_CASE_PROPERTIES = {
    "Solver": ("solver", "App::PropertyEnumeration", openfoam_case.DEFAULT_SOLVER,
               "rhoPimpleFoam (pressure-based, local time stepping), rhoSimpleFoam, or rhoCentralFoam "
               "(density-based, explicit; euler grids only)"),
    "Mach": ("mach", "App::PropertyFloat", openfoam_case.M6_MACH, "Free-stream Mach number"),
    "AngleOfAttack": ("alpha_degrees", "App::PropertyAngle", openfoam_case.M6_ALPHA_DEGREES,
                      "Angle of attack in the x-z plane (y the span direction)"),
    "Temperature": ("temperature", "App::PropertyFloat", openfoam_case.M6_TEMPERATURE, "Free-stream temperature (K)"),
    "Pressure": ("pressure", "App::PropertyFloat", 0.0,
                 "Free-stream pressure (Pa); 0: set from the volume mesh's Reynolds number on the reference "
                 "length for a rans grid, 1e5 Pa for an euler one"),
    "Iterations": ("iterations", "App::PropertyInteger", openfoam_case.DEFAULT_ITERATIONS,
                   "Solver steps the case runs"),
    "ReferenceLength": ("reference_length", "App::PropertyLength", openfoam_case.M6_REFERENCE_LENGTH / METRES_PER_MM,
                        "Force coefficients' reference length (and the Reynolds number's)"),
    "ReferenceArea": ("reference_area", "App::PropertyArea", openfoam_case.M6_REFERENCE_AREA / METRES_PER_MM**2,
                      "Force coefficients' reference area"),
    "MomentPoint": ("moment_point", "App::PropertyVector",
                    tuple(c / METRES_PER_MM for c in openfoam_case.M6_MOMENT_POINT),
                    "Point the moment coefficient is taken about"),
}


def flow_case_options(obj):
    """openfoam_case.write_case's keywords from the object's flow-case properties (in metres)."""
    options = {}
    for name, (keyword, _, _, _) in FLOW_CASE_PROPERTIES.items():
        value = getattr(obj, name)
        value = getattr(value, "Value", value)  # quantities in mm, mm^2, degrees
        if name == "ReferenceLength":
            value *= METRES_PER_MM
        elif name == "ReferenceArea":
            value *= METRES_PER_MM**2
        elif name == "MomentPoint":
            value = tuple(METRES_PER_MM * c for c in value)
        options[keyword] = value
    if options["pressure"] == 0.0:
        options["pressure"] = None
    return options


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


def write(source, file_format, path, force=False, flow_case=None):
    """Writes a VolumeGrid (or, for gismo / blocks, a VolumeMesh or the mesh of a VolumeGrid).
    flow_case: openfoam_case.write_case's keywords for the openfoam_case format."""
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
            rans = source.Preset == "rans"
            openfoam_case.write_case(refined, path, model="rans" if rans else "euler",
                                     reynolds_number=source.VolumeMesh.ReynoldsNumber if rans else None,
                                     length_unit=METRES_PER_MM, force=force, **(flow_case or {}))
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
        self.add_enumeration(obj, "Format", "Export", "File format", FORMATS, "cgns")
        add_property(obj, "App::PropertyString", "Path", "Export",
                     "File (or OpenFOAM case directory) written on recompute")
        add_property(obj, "App::PropertyBool", "Force", "Export",
                     "Write even a grid with non-positive cells (refused otherwise)", False)
        add_property(obj, "App::PropertyString", "Written", "Result", "Digest of the grid last written",
                     mode=READ_ONLY)
        for name, (_, type_name, default, tooltip) in FLOW_CASE_PROPERTIES.items():
            if type_name == "App::PropertyEnumeration":  # the solver
                self.add_enumeration(obj, name, FLOW_CASE_GROUP, tooltip, openfoam_case.SOLVERS, default)
            elif name not in obj.PropertiesList:  # a restored document keeps its values
                obj.addProperty(type_name, name, FLOW_CASE_GROUP, tooltip)
                setattr(obj, name, default)
        self.show_flow_case(obj)

    @staticmethod
    def show_flow_case(obj):
        mode = 0 if obj.Format == "openfoam_case" else HIDDEN
        for name in FLOW_CASE_PROPERTIES:
            if name in obj.PropertiesList:
                obj.setEditorMode(name, mode)

    def onChanged(self, obj, prop):
        super().onChanged(obj, prop)
        if prop == "Format":
            self.show_flow_case(obj)

    def compute(self, obj):
        if obj.Source is None:
            raise ValueError("the export needs a source")
        flow_case = flow_case_options(obj) if obj.Format == "openfoam_case" else None
        write(obj.Source, obj.Format, obj.Path, obj.Force, flow_case)
        obj.Written = obj.Source.Digest


def create(doc, name="Export"):
    obj = doc.addObject("App::FeaturePython", name)
    ExportProxy(obj)
    return obj
