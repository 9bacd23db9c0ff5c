"""The machine's free memory and the budgets drawn from it: a grid or a fit level that would need
more is refused (or ends the fit) before it is allocated, instead of running the session, and a
FreeCAD document with it, out of memory."""


def available_bytes():
    """The kernel's estimate of the memory a new allocation can take (MemAvailable), or None where
    it is not known."""
    try:
        with open("/proc/meminfo") as info:
            for line in info:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return None


def budget(bytes_per_item):
    """How many items of bytes_per_item the available memory holds; 0 (no limit) where it is not
    known."""
    available = available_bytes()
    return available // bytes_per_item if available is not None else 0
