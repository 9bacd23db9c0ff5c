"""Where BVMesh's files are: the checkout (or installed workbench) root and its resources."""

import os

PACKAGE_DIR = os.path.dirname(os.path.abspath(__file__))
ROOT_DIR = os.path.dirname(os.path.dirname(PACKAGE_DIR))
RESOURCES_DIR = os.path.join(ROOT_DIR, "resources")
ICONS_DIR = os.path.join(RESOURCES_DIR, "icons")
EXAMPLE_DATA_DIR = os.path.join(ROOT_DIR, "tests", "data")
EXAMPLE_WING = os.path.join(EXAMPLE_DATA_DIR, "AileM6_with_sharp_TE.stp")


def icon(name):
    """Absolute path of resources/icons/<name>.svg."""
    return os.path.join(ICONS_DIR, name + ".svg")
