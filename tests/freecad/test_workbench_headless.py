"""The workbench as freecadcmd loads it: Init.py runs headless and makes the package importable."""

import os
import subprocess
import sys
import tempfile
import unittest

import FreeCAD


class HeadlessWorkbench(unittest.TestCase):
    def test_init_py_put_the_package_on_sys_path(self):
        # The test home registers this checkout as Mod/BVMesh; Init.py adds its Mod/ folder.
        registered = os.path.join(FreeCAD.getUserAppDataDir(), "Mod", "BVMesh", "Mod")
        self.assertIn(registered, sys.path)

    def test_package_xml_declares_the_workbench(self):
        root = os.environ["BVMESH_SOURCE_DIR"]
        metadata = FreeCAD.Metadata(os.path.join(root, "package.xml"))
        self.assertEqual(metadata.Name, "BVMesh")
        workbenches = metadata.Content["workbench"]
        self.assertEqual(len(workbenches), 1)
        self.assertEqual(workbenches[0].Classname, "BVMeshWorkbench")
        self.assertTrue(os.path.isfile(os.path.join(root, workbenches[0].Icon)))

    def test_command_line_main_job_reports_and_fails_cleanly(self):
        env = dict(os.environ, PYTHONPATH=os.pathsep.join(
            [os.path.join(os.environ["BVMESH_SOURCE_DIR"], "Mod"), "/usr/lib/freecad-python3/lib"]))
        output = tempfile.mkdtemp(prefix="bvmesh-example-")
        done = subprocess.run(["/usr/bin/python3", "-m", "bvmesh", "example", "--output", output, "--max-level", "1",
                               "--surface-only"], env=env, capture_output=True, text=True, timeout=300)
        # Level 1 is above the tolerance: the files are written, exit status 2 and a warning say so.
        self.assertEqual(done.returncode, 2, done.stderr)
        self.assertIn("bvmesh: warning: the fit stopped as max_level: at level 1: samples up to", done.stderr)
        self.assertIn("11 faces (8 BSplineSurface, 3 Plane)", done.stdout)
        self.assertTrue(os.path.isfile(os.path.join(output, "M6.FCStd")))
        # At level 1 the boundary layer folds at the tip's trailing-edge corner: the volume stage
        # says where, exits 1 without a traceback, and keeps the surface stage's document.
        folded = tempfile.mkdtemp(prefix="bvmesh-example-")
        failed = subprocess.run(["/usr/bin/python3", "-m", "bvmesh", "example", "--output", folded, "--max-level", "1"],
                                env=env, capture_output=True, text=True, timeout=300)
        self.assertEqual(failed.returncode, 1, failed.stderr)
        self.assertRegex(failed.stderr, r"bvmesh: VolumeMesh failed: SolverError: marching folds at layer \d+")
        self.assertNotIn("Traceback", failed.stderr)
        self.assertTrue(os.path.isfile(os.path.join(folded, "M6.FCStd")))
        missing = subprocess.run(["/usr/bin/python3", "-m", "bvmesh", "info", "/no/such/wing.step"], env=env,
                                 capture_output=True, text=True, timeout=300)
        self.assertEqual(missing.returncode, 1)
        self.assertIn("does not exist", missing.stderr)


if __name__ == "__main__":
    unittest.main()
