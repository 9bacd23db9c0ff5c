"""The B-spline shell: the limit surface of a surface fit converted to B-spline faces by the core
(bvmesh.extensions.limit_surface_to_shell), as a Part shape ready for STEP export."""

from bvmesh.features.common import READ_ONLY, Proxy, add_property

TYPE = "BVMesh::BsplineShell"


class BsplineShellProxy(Proxy):
    Type = TYPE

    def setup(self, obj):
        add_property(obj, "App::PropertyLink", "Fit", "B-spline shell", "The surface fit to convert")
        add_property(obj, "App::PropertyBool", "TangentContinuity", "B-spline shell",
                     "Neighbouring faces share their tangent planes along smooth borders (to below 0.1 degree "
                     "but at cone points), at the cost of distance from the limit surface next to extraordinary "
                     "vertices (docs/fitting.md)", False)
        add_property(obj, "App::PropertyFloat", "MaxDistance", "Result",
                     "Largest distance of the B-spline faces from the fitted limit surface (at 9 x 9 points per "
                     "control face, along the limit normal)", mode=READ_ONLY)
        add_property(obj, "App::PropertyFloat", "MaxKinkDegrees", "Result",
                     "Largest angle between the normals of neighbouring faces along their smooth borders",
                     mode=READ_ONLY)

    def compute(self, obj):
        from bvmesh import extensions
        from bvmesh.features import surface_fit

        if obj.Fit is None or not obj.Fit.ControlVertices:
            raise ValueError("the B-spline shell needs a computed surface fit")
        obj.Shape, report = extensions.limit_surface_to_shell(surface_fit.result_mesh(obj.Fit),
                                                              tangent_continuity=obj.TangentContinuity)
        obj.MaxDistance = report["max_distance"]
        obj.MaxKinkDegrees = report["max_kink_degrees"]


def create(doc, name="BsplineShell"):
    obj = doc.addObject("Part::FeaturePython", name)
    BsplineShellProxy(obj)
    return obj
