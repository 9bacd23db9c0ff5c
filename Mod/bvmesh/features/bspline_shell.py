"""The B-spline shell: the limit surface of a surface fit converted to B-spline faces by the core
(bvmesh.extensions.limit_surface_to_shell), as a Part shape ready for STEP export."""

from bvmesh.features.common import Proxy, add_property

TYPE = "BVMesh::BsplineShell"


class BsplineShellProxy(Proxy):
    Type = TYPE

    def setup(self, obj):
        add_property(obj, "App::PropertyLink", "Fit", "B-spline shell", "The surface fit to convert")

    def compute(self, obj):
        from bvmesh import extensions
        from bvmesh.features import surface_fit

        if obj.Fit is None or not obj.Fit.ControlVertices:
            raise ValueError("the B-spline shell needs a computed surface fit")
        obj.Shape = extensions.limit_surface_to_shell(surface_fit.result_mesh(obj.Fit))


def create(doc, name="BsplineShell"):
    obj = doc.addObject("Part::FeaturePython", name)
    BsplineShellProxy(obj)
    return obj
