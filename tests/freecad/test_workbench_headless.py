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
        done = subprocess.run(["/usr/bin/python3", "-m", "bvmesh", "example", "--output", output, "--max-level", "1"],
                              env=env,
                              capture_output=True, text=True, timeout=300)
        self.assertEqual(done.returncode, 0, done.stderr)
        self.assertIn("11 faces (8 BSplineSurface, 3 Plane)", done.stdout)
        missing = subprocess.run(["/usr/bin/python3", "-m", "bvmesh", "info", "/no/such/wing.step"], env=env,
                                 capture_output=True, text=True, timeout=300)
        self.assertEqual(missing.returncode, 1)
        self.assertIn("does not exist", missing.stderr)


if __name__ == "__main__":
    unittest.main()
