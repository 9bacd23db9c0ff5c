"""Every function and method the compiled module offers, called with malformed arguments: each
argument in turn replaced by a value of the wrong kind, shape, size or range (NaN and infinite
arrays, empty and ragged arrays, ids out of range, huge counts, unwritable and undecodable paths).
Whatever the call does (a result or a Python exception), it must not take the interpreter down:
a crash in a binding is a FreeCAD session lost with the user's document. Each call runs in a
forked child, so a crash is reported by name instead of ending the test run; a call that runs
longer than a time limit counts as a hang."""

import ctypes
import os
import signal
import tempfile
import unittest

import numpy as np

import bvmesh
import bvmesh.grid
import bvmesh.volume
from bvmesh import _core
from fixtures import CUBE_FACES, CUBE_VERTICES, sphere_target

SECONDS = 30
TEMPLATES = os.path.join(os.environ.get("BVMESH_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", "..")),
                         "resources", "templates")

MALFORMED = [
    None, -1, 0, 2**31, 2**63 - 1, float("nan"), float("inf"), -float("inf"), 1e308, True, "", "x" * 10000, "\x00",
    b"\xff\xfe", [], [[]], {}, [[0, 1, 2, 99]], [[0, 0, 0, 0]], [[0, 1]], [[-5, 1, 2, 3]],
    np.zeros(0), np.zeros((0, 3)), np.full((4, 3), np.nan), np.full((4, 3), np.inf), np.ones((10, 3)) * 1e300,
    np.zeros((3, 4)), np.zeros((2, 2, 2)), np.zeros(5, dtype=np.int64), np.array([-1, 5, 10**9]), np.array(["a"]),
    np.zeros((4, 3))[:, ::2], np.array(2.0),
]


def outcome_in_child(call, seconds=SECONDS, folder=None):
    """None when `call()` returned or raised an Exception in a forked child (working in `folder`,
    where relative paths land); else what happened."""
    pid = os.fork()
    if pid == 0:  # pragma: no cover - the child's exit status is the result
        code = 0
        try:
            if folder:
                os.chdir(folder)
            signal.alarm(seconds)
            call()
        except Exception:
            pass
        except BaseException:
            code = 3
        os._exit(code)
    _, status = os.waitpid(pid, 0)
    if os.WIFSIGNALED(status):
        number = os.WTERMSIG(status)
        return "a hang (over {} s)".format(seconds) if number == signal.SIGALRM else \
            "signal {} ({})".format(number, signal.Signals(number).name)
    return None if os.WEXITSTATUS(status) == 0 else "exit status {}".format(os.WEXITSTATUS(status))


def describe(value):
    if isinstance(value, np.ndarray):
        return "array{}{}".format(value.shape, value.dtype)
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


@unittest.skipUnless(hasattr(os, "fork"), "needs fork")
class MalformedArguments(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.folder = tempfile.TemporaryDirectory()
        cls.scratch = os.path.join(cls.folder.name, "scratch")  # the children's working folder
        os.makedirs(cls.scratch)
        target = sphere_target()
        cube = bvmesh.ControlMesh(CUBE_VERTICES, CUBE_FACES)
        fitter = bvmesh.SurfaceFitter(target, bvmesh.ControlMesh(CUBE_VERTICES, CUBE_FACES), max_level=1)
        fitter.run()
        wall = fitter.mesh
        volume = bvmesh.volume.offset_and_farfield(fitter, boundary_layer_thickness=0.05, farfield_distance=20.0)
        blocks = volume.blocks
        grid = bvmesh.grid.refine(volume, "euler", edge_points=5, normal_points=9).grid
        marching = dict(boundary_layer_thickness=0.05, farfield_distance=20.0)
        control = _core.control_volume_mesh(wall, **marching)
        marching.update(symmetry_plane=None, outflow_plane=None)  # both planes' parsing fuzzed too
        points = np.asarray(CUBE_VERTICES, float)
        path = lambda name: os.path.join(cls.folder.name, name)  # noqa: E731
        blocks.write(path("blocks.txt"))
        # Unwritable even for root: a folder below a file.
        cls.malformed = MALFORMED + [path("blocks.txt/folder/file")]
        _core.write_plot3d(grid, path("grid.xyz"))
        cube.write(path("cube.txt"))
        samples = cube.limit_samples()
        evaluator = _core.LimitEvaluator(cube)
        brep = _core.bspline_face_brep(np.zeros((4, 4, 3)) + np.arange(4)[:, None, None] * [1, 0, 0]
                                       + np.arange(4)[None, :, None] * [0, 1, 0], 3, 3, [0.0, 1.0], [0.0, 1.0],
                                       [4, 4], [4, 4])
        half = [0.0, 1.0]
        # name -> (callable, valid positional arguments, valid keyword arguments)
        cls.calls = {
            "ControlMesh": (bvmesh.ControlMesh, [CUBE_VERTICES, CUBE_FACES], {}),
            "ControlMesh.vertices": (lambda v: setattr(bvmesh.ControlMesh(CUBE_VERTICES, CUBE_FACES), "vertices", v),
                                     [points], {}),
            "ControlMesh.evaluate": (cube.evaluate, [np.array([0, 1]), np.array([0.5, 0.5]), np.array([0.5, 0.5])], {}),
            "ControlMesh.subdivide": (cube.subdivide, [], {}),
            "ControlMesh.limit_samples": (cube.limit_samples, [], {}),
            "ControlMesh.write": (cube.write, [path("written.txt")], {}),
            "SubdivisionOptions": (_core.SubdivisionOptions, [], {}),
            "LimitEvaluator": (_core.LimitEvaluator, [cube], {}),
            "LimitEvaluator.evaluate": (evaluator.evaluate, [points, np.array([0]), np.array([0.5]), np.array([0.5])], {}),
            "LimitSamples": (_core.LimitSamples, [cube], {}),
            "LimitSamples.positions_for": (samples.positions_for, [points], {}),
            "LimitSamples.normals_for": (samples.normals_for, [points], {}),
            "SurfaceFitter": (bvmesh.SurfaceFitter, [target, cube], {}),
            "SurfaceFitter.run": (fitter.run, [], dict(max_level=1)),
            "SurfaceFitter.set_options": (fitter.set_options, [], {name: value for name, value in fitter.options.items()}),
            "SurfaceFitter.set_vertices": (fitter.set_vertices, [np.asarray(wall.vertices)], {}),
            "SurfaceFitter.mesh_at_level": (fitter.mesh_at_level, [0], {}),
            "SurfaceFitter.smooth": (fitter.smooth, [3, 0.6307, -0.6732], {}),
            "SurfaceFitter.two_sided_distance": (fitter.two_sided_distance, [4, 0], {}),
            "SurfaceFitter.correct_parameters": (fitter.correct_parameters, [1], {}),
            "SurfaceFitter.approximate": (fitter.approximate, [], {}),
            "SurfaceFitter.compute_limit_samples": (fitter.compute_limit_samples, [], {}),
            "SurfaceFitter.project": (fitter.project, [], {}),
            "SurfaceFitter.record": (fitter.record, [True], {}),
            "SurfaceFitter.subdivide": (bvmesh.SurfaceFitter(target, cube, max_level=1).subdivide, [], {}),
            "Target.from_brep": (bvmesh.Target.from_brep, [brep], {}),
            "Target.from_file": (bvmesh.Target.from_file, [path("blocks.txt")], {}),
            "Target.project": (target.project, [points], {}),
            "Target.project_along": (target.project_along, [points, points], {}),
            "Target.project_to_edges": (target.project_to_edges, [points, [0]], {}),
            "Target.project_to_free_boundary": (target.project_to_free_boundary, [points], {}),
            "Target.project_to_vertex": (target.project_to_vertex, [points, [0]], {}),
            "Target.sharp_edges": (target.sharp_edges, [30.0], {}),
            "Target.free_edges": (target.free_edges, [], {}),
            "Target.report": (target.report, [], {}),
            "Target.vertex_position": (target.vertex_position, [0], {}),
            "BlockMesh.evaluate": (blocks.evaluate, [0, np.array([[0.5, 0.5, 0.5]])], {}),
            "BlockMesh.evaluate_grid": (blocks.evaluate_grid, [0, half, half, half], {}),
            "BlockMesh.poles": (blocks.poles, [0], {}),
            "BlockMesh.knots": (blocks.knots, [0], {}),
            "BlockMesh.faces": (blocks.faces, [0], {}),
            "BlockMesh.degrees": (blocks.degrees, [0], {}),
            "BlockMesh.control_mesh": (blocks.control_mesh, [], {}),
            "BlockMesh.write": (blocks.write, [path("written_blocks.txt")], {}),
            "ControlVolume.hex_mesh": (control.hex_mesh, [], {}),
            "StructuredGrid.points": (grid.points, [0], {}),
            "StructuredGrid.size": (grid.size, [0], {}),
            "StructuredGrid.faces": (grid.faces, [0], {}),
            "StructuredGrid.quad_conditions": (grid.quad_conditions, [0, "w_min"], {}),
            "StructuredGrid.merged_points": (grid.merged_points, [], {}),
            "bspline_face_brep": (_core.bspline_face_brep, [np.zeros((4, 4, 3)), 3, 3, half, half, [4, 4], [4, 4]], {}),
            "check_brep_text": (_core.check_brep_text, [brep], {}),
            "control_volume_mesh": (_core.control_volume_mesh, [wall], marching),
            "feature_curves": (_core.feature_curves, [target], {}),
            "flat_plate_boundary_layer_thickness": (_core.flat_plate_boundary_layer_thickness, [1e6, 1.0], {}),
            "generate_volume_mesh": (_core.generate_volume_mesh, [wall], marching),
            "grid_plane_cut": (_core.grid_plane_cut, [grid, np.zeros(3), np.array([0.0, 1.0, 0.0])], {}),
            "grid_quality": (_core.grid_quality, [grid], {}),
            "hex_mesh_of_blocks": (_core.hex_mesh_of_blocks, [blocks], {}),
            "improve_polyhedron": (_core.improve_polyhedron, [cube, target], {}),
            "limit_surface_to_bsplines": (_core.limit_surface_to_bsplines, [cube], {}),
            "map_features": (_core.map_features, [cube, target], {}),
            "overlapping_solids": (_core.overlapping_solids, [brep], {}),
            "place_template": (_core.place_template, [os.path.join(TEMPLATES, "sphere.template"), target], {}),
            "read_block_mesh": (_core.read_block_mesh, [path("blocks.txt")], {}),
            "read_cad_file": (_core.read_cad_file, [path("blocks.txt")], {}),
            "read_cad_file_as_brep": (_core.read_cad_file_as_brep, [path("blocks.txt")], {}),
            "read_control_mesh": (_core.read_control_mesh, [path("cube.txt")], {}),
            "read_plot3d": (_core.read_plot3d, [path("grid.xyz")], {}),
            "read_template_library": (_core.read_template_library, [TEMPLATES], {}),
            "refine_blocks": (_core.refine_blocks, [blocks], dict(edge_points=5, normal_points=9)),
            "remove_symmetry_face": (_core.remove_symmetry_face, [brep], {}),
            "select_faces": (_core.select_faces, [brep, [0]], {}),
            "split_flow_domain": (_core.split_flow_domain, [brep], {}),
            "subdivide_and_fit_volume": (_core.subdivide_and_fit_volume, [control.hex_mesh(), target, 1], {}),
            "subdivide_blocks": (_core.subdivide_blocks, [blocks, 1], {}),
            "subdivide_control_volume": (_core.subdivide_control_volume, [control, 1], {}),
            "subdivide_hex_mesh": (_core.subdivide_hex_mesh, [_core.hex_mesh_of_blocks(blocks)], {}),
            "summarize_brep": (_core.summarize_brep, [brep], {}),
            "summarize_file": (_core.summarize_file, [path("blocks.txt")], {}),
            "symmetry_plane": (_core.symmetry_plane, [target], {}),
            "write_cgns": (_core.write_cgns, [grid, path("grid.cgns")], {}),
            "write_control_mesh": (_core.write_control_mesh, [cube, path("mesh.txt")], {}),
            "write_gismo": (_core.write_gismo, [blocks, path("blocks.xml")], {}),
            "write_iges_faces": (_core.write_iges_faces, [[brep], path("faces.igs")], {}),
            "write_openfoam": (_core.write_openfoam, [grid, path("case")], {}),
            "write_plot3d": (_core.write_plot3d, [grid, path("written.xyz")], {}),
            "write_vtk": (_core.write_vtk, [grid, path("grid.vtm")], {}),
        }

    @classmethod
    def tearDownClass(cls):
        cls.folder.cleanup()

    def test_the_child_reports_crashes_and_hangs(self):
        self.assertIsNone(outcome_in_child(lambda: int("not a number")))
        # A read through a null pointer: a handler the loaded libraries install turns SIGSEGV into exit(1).
        self.assertIn(outcome_in_child(lambda: ctypes.string_at(0)), ("exit status 1", "signal 11 (SIGSEGV)"))
        self.assertEqual(outcome_in_child(os.abort), "signal 6 (SIGABRT)")
        self.assertEqual(outcome_in_child(lambda: signal.pause(), seconds=1), "a hang (over 1 s)")

    def test_every_binding_is_in_the_table(self):
        # A binding added without a line here would go unchecked.
        public = set()
        for name in dir(_core):
            item = getattr(_core, name)
            if name.startswith("_") or (isinstance(item, type) and issubclass(item, BaseException)):
                continue
            if not isinstance(item, type):
                public.add(name)
                continue
            if "__members__" in vars(item):  # an enumeration
                continue
            if "__init__(self" in (item.__init__.__doc__ or ""):  # a class with a constructor
                public.add(name)
            public.update("{}.{}".format(name, m) for m in dir(item) if not m.startswith("_")
                          and not isinstance(getattr(item, m), (property, type)) and callable(getattr(item, m)))
        public.add("ControlMesh.vertices")  # a property that may be assigned
        self.assertEqual(sorted(public - set(self.calls)), [])

    def test_malformed_arguments_never_crash(self):
        crashes = []
        for name, (function, arguments, keywords) in self.calls.items():
            happened = outcome_in_child(lambda: function(*arguments, **keywords), folder=self.scratch)
            if happened:
                crashes.append("{} with its valid arguments: {}".format(name, happened))
            slots = [(i, None) for i in range(len(arguments))] + [(None, k) for k in keywords]
            for index, keyword in slots:
                for value in self.malformed:
                    changed, changed_keywords = list(arguments), dict(keywords)
                    if keyword is None:
                        changed[index] = value
                    else:
                        changed_keywords[keyword] = value

                    happened = outcome_in_child(lambda: function(*changed, **changed_keywords),
                                                folder=self.scratch)
                    if happened:
                        crashes.append("{} with {} = {}: {}".format(
                            name, "argument {}".format(index) if keyword is None else keyword, describe(value),
                            happened))
        self.assertEqual(crashes, [])


if __name__ == "__main__":
    unittest.main()
