"""BVMesh's FreeCAD document objects (feature python): target, control polyhedron, surface fit,
distance map and B-spline shell. Headless: view providers live in bvmesh.gui and are attached by
bvmesh.api only when FreeCAD.GuiUp."""
