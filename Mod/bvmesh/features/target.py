"""The CAD target: the faces of a CAD object that the surface is fitted to (e.g. all faces of a
half wing except its root face on the symmetry plane). Its Shape is the compound of those faces;
Report summarizes what the core sees in them."""

import hashlib

import Part

from bvmesh.features.common import HIDDEN, READ_ONLY, Proxy, add_property

TYPE = "BVMesh::Target"


def fitted_faces(source_shape, face_names):
    """The faces named (Face<i>) of `source_shape`, or all of its faces when none are named."""
    if not face_names:
        return list(source_shape.Faces)
    faces = []
    for name in face_names:
        if not name.startswith("Face"):
            raise ValueError("target faces must be named Face<i>, got '{}'".format(name))
        faces.append(source_shape.getElement(name))
    return faces


def same_geometry(a, b, relative_tolerance=1e-9):
    """True when shapes a and b have the same faces, edges and vertices and their vertices and
    face areas agree to relative_tolerance of the size (the round-off of saving a document)."""
    if (len(a.Faces), len(a.Edges), len(a.Vertexes)) != (len(b.Faces), len(b.Edges), len(b.Vertexes)):
        return False
    tolerance = relative_tolerance * max(a.BoundBox.DiagonalLength, 1e-300)
    if any((u.Point - v.Point).Length > tolerance for u, v in zip(a.Vertexes, b.Vertexes)):
        return False
    return all(abs(f.Area - g.Area) <= relative_tolerance * max(f.Area, 1e-300) for f, g in zip(a.Faces, b.Faces))


class TargetProxy(Proxy):
    Type = TYPE

    def setup(self, obj):
        add_property(obj, "App::PropertyLink", "Source", "Target", "The CAD object to fit")
        add_property(obj, "App::PropertyStringList", "Faces", "Target",
                     "Faces of Source to fit (Face<i>); empty: all faces, or the body's when Source is a flow "
                     "domain's CAD (a box or sphere with the body cut out)")
        add_property(obj, "App::PropertyFloat", "SharpAngle", "Target",
                     "Edges whose faces meet at this angle (degrees) or more are sharp", 30.0)
        add_property(obj, "App::PropertyFloat", "RelativeDeflection", "Target",
                     "Tessellation deflection of the projection index, relative to the model size", 1e-3)
        add_property(obj, "App::PropertyStringList", "Report", "Result",
                     "What the core finds in the fitted faces", mode=READ_ONLY)
        add_property(obj, "App::PropertyString", "FlowDomain", "Flow domain",
                     "The domain of a flow domain's CAD: box or sphere (its body fitted); empty: not one",
                     mode=READ_ONLY)
        add_property(obj, "App::PropertyVector", "DomainCentre", "Flow domain",
                     "Centre of the flow domain (on its symmetry plane for a half domain)", mode=READ_ONLY)
        add_property(obj, "App::PropertyVector", "DomainSize", "Flow domain",
                     "A box domain's half sizes (from the symmetry plane for a half box), a sphere's radius thrice",
                     mode=READ_ONLY)
        add_property(obj, "App::PropertyVector", "SymmetryPoint", "Flow domain",
                     "A point of the flow domain's symmetry plane that the body lies on", mode=READ_ONLY)
        add_property(obj, "App::PropertyVector", "SymmetryNormal", "Flow domain",
                     "The symmetry plane's normal, towards the domain; zero: a whole body", mode=READ_ONLY)
        add_property(obj, "App::PropertyVector", "OutflowPoint", "Flow domain",
                     "A point of the domain's outflow plane that the body runs into (a sting)", mode=READ_ONLY)
        add_property(obj, "App::PropertyVector", "OutflowNormal", "Flow domain",
                     "The outflow plane's normal, towards the domain; zero: the body does not run into one",
                     mode=READ_ONLY)
        add_property(obj, "App::PropertyString", "Geometry", "Result",
                     "BREP text of the fitted faces, exactly as the core gets it", mode=HIDDEN)
        add_property(obj, "App::PropertyString", "BrepHash", "Result",
                     "SHA-1 of Geometry (identifies the target)", mode=HIDDEN)

    def compute(self, obj):
        from bvmesh import api, load_core

        if obj.Source is None or not hasattr(obj.Source, "Shape") or obj.Source.Shape.isNull():
            raise ValueError("the target needs a Source object with a shape")
        source = obj.Source.Shape  # exported to BREP once, for both checks, where both run
        if len(obj.Source.Shape.Solids) > 1:
            source = obj.Source.Shape.exportBrepToString()
            overlaps = load_core().overlapping_solids(source)
            if overlaps:
                raise ValueError("the Source {} holds {}".format(
                    obj.Source.Label, api.overlapping_solids_message(overlaps)))
        faces = list(obj.Faces)
        domain = None if faces else api.flow_domain_of(source)
        if domain is not None:
            faces = ["Face{}".format(i + 1) for i in domain["body_faces"]]
        self.set_flow_domain(obj, domain)
        # A copy without triangulation: display meshes must not reach the core.
        fresh = Part.makeCompound(fitted_faces(obj.Source.Shape, faces)).copy(True, False)
        # Saving a document rounds shapes in the last digits. The target keeps the exact geometry
        # it was made from unless the source really changed, so a reopened document recomputes
        # to identical results.
        kept = self.kept_geometry(obj)
        if kept is None or not same_geometry(fresh, kept):
            obj.Geometry = fresh.exportBrepToString()
            obj.BrepHash = hashlib.sha1(obj.Geometry.encode()).hexdigest()
        obj.Shape = fresh
        obj.Report = api.format_target_report(self.core_target(obj).report())

    @staticmethod
    def kept_geometry(obj):
        """The shape of obj.Geometry, or None when there is none or it is unreadable (then rebuilt
        from Source, with a warning). Read through the core's child process: Geometry is document
        text, and BREP text cut near its end makes OpenCASCADE's reader loop, in FreeCAD's own
        process a hang."""
        from bvmesh import load_core
        from bvmesh.adapters.shapes import brep_to_shape

        if not obj.Geometry:
            return None
        try:
            return brep_to_shape(load_core().check_brep_text(obj.Geometry))
        except ValueError as error:
            import FreeCAD

            FreeCAD.Console.PrintWarning("BVMesh: {}'s hidden Geometry is no shape ({}); rebuilt from its Source "
                                         "{}\n".format(obj.Label, error, obj.Source.Label))
            return None

    @staticmethod
    def set_flow_domain(obj, domain):
        import FreeCAD

        from bvmesh import polyhedra

        obj.FlowDomain = domain["shape"] if domain else ""
        obj.DomainCentre = FreeCAD.Vector(*domain["centre"]) if domain else FreeCAD.Vector()
        obj.DomainSize = FreeCAD.Vector(*polyhedra.domain_size(domain)) if domain else FreeCAD.Vector()
        for prefix, key in (("Symmetry", "symmetry_plane"), ("Outflow", "outflow_plane")):
            plane = domain[key] if domain else None
            setattr(obj, prefix + "Point", FreeCAD.Vector(*plane[0]) if plane else FreeCAD.Vector())
            setattr(obj, prefix + "Normal", FreeCAD.Vector(*plane[1]) if plane else FreeCAD.Vector())

    def core_target(self, obj):
        """The bvmesh.Target of the fitted faces, built once per geometry and options."""
        from bvmesh import load_core, preferences

        key = (obj.BrepHash, obj.RelativeDeflection, obj.SharpAngle)
        cached = getattr(self, "_cache", None)
        if cached is not None and cached[0] == key:
            return cached[1]
        target = load_core().Target.from_brep(
            obj.Geometry, relative_deflection=obj.RelativeDeflection, sharp_angle_deg=obj.SharpAngle,
            threads=preferences.threads())
        self._cache = (key, target)
        return target


def create(doc, name="Target"):
    obj = doc.addObject("Part::FeaturePython", name)
    TargetProxy(obj)
    return obj
