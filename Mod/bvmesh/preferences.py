"""BVMesh's user preferences, stored by FreeCAD under
User parameter:BaseApp/Preferences/Mod/BVMesh (edited on the BVMesh preference page). Commands
read them to fill in defaults and pass the values explicitly, so recorded macros do not depend on
the preferences of the machine that replays them."""

import FreeCAD

PATH = "User parameter:BaseApp/Preferences/Mod/BVMesh"

# name: (kind, default)
DEFAULTS = {
    "RelativeTolerance": ("float", 1e-4),
    "MaxLevel": ("int", 4),
    "Threads": ("int", 0),
    "CreaseColor": ("color", (0.85, 0.1, 0.1)),
    "EdgeColor": ("color", (0.1, 0.1, 0.1)),
}


def group():
    return FreeCAD.ParamGet(PATH)


def _packed(rgb):
    r, g, b = (int(round(255 * c)) for c in rgb)
    return (r << 24) | (g << 16) | (b << 8)


def get(name):
    kind, default = DEFAULTS[name]
    params = group()
    if kind == "float":
        return params.GetFloat(name, default)
    if kind == "int":
        return params.GetInt(name, default)
    # Colours are stored as Gui::PrefColorButton does: unsigned 0xRRGGBBAA.
    packed = params.GetUnsigned(name, _packed(default))
    return tuple(((packed >> shift) & 0xFF) / 255.0 for shift in (24, 16, 8))


def relative_tolerance():
    return get("RelativeTolerance")


def max_level():
    return get("MaxLevel")


def threads():
    """Threads of the core's target index; 0: every hardware thread."""
    return get("Threads")


def crease_color():
    return get("CreaseColor")


def edge_color():
    return get("EdgeColor")
