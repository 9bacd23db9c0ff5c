"""Helpers shared by the document objects: property set-up that is safe to run twice (at
creation and again in onDocumentRestored, so files written by older versions gain new
properties), a proxy base that persists nothing of its own, and the hook through which long
computations run (in the GUI: a worker thread with progress and Cancel)."""

import collections
import contextlib

# Document.Meta key: names of the objects a document written headless shows when opened in the GUI.
VISIBLE_ON_OPEN = "BVMesh_VisibleOnOpen"

# Editor modes of FreeCAD's property editor.
READ_ONLY = 1
HIDDEN = 2


# The block-face conditions each display switch (ShowWall, ShowSymmetry, ShowFarfield) shows: the
# far field stands for the whole domain boundary, a box's inlet, outlet and side faces and the
# outflow plane a body runs into included.
SHOWN_CONDITIONS = {"wall": ("wall",), "symmetry": ("symmetry",), "farfield": ("farfield", "inlet", "outlet", "side")}


def shown_conditions(obj, display):
    """The block-face conditions an object's display switches (`display`: (property, switch,
    default) rows) show."""
    return {shown for prop, switch, _ in display if getattr(obj, prop) for shown in SHOWN_CONDITIONS[switch]}


def add_property(obj, type_name, name, group, doc, default=None, mode=None):
    """Adds property `name` unless it exists; sets `default` only when it was added, so a
    restored document keeps its values."""
    if name not in obj.PropertiesList:
        obj.addProperty(type_name, name, group, doc)
        if default is not None:
            setattr(obj, name, default)
    if mode is not None:
        obj.setEditorMode(name, mode)


def upstream(start):
    """(object, the object linking it) for every object `start` depends on (its OutList, theirs,
    ...), nearest first, each once: start itself too when it is on a dependency cycle."""
    seen = set()
    queue = collections.deque([start])
    while queue:
        current = queue.popleft()
        for linked in current.OutList:
            if linked.FullName not in seen:
                seen.add(linked.FullName)
                queue.append(linked)
                yield linked, current


def link_path(start, goal):
    """The shortest chain of links from `start` to `goal` as a list of objects, both ends
    included, or None; with start == goal, a dependency cycle through it."""
    linker = {}
    for obj, by in upstream(start):
        linker[obj.FullName] = by
        if obj.FullName == goal.FullName:
            path = [obj, by]
            while path[-1].FullName != start.FullName:
                path.append(linker[path[-1].FullName])
            return path[::-1]
    return None


def describe_path(path):
    return " -> ".join(obj.Label for obj in path)


def describe_choices(choices):
    return "[{}]".format(", ".join(choices))


def property_sizes(obj):
    """{property: size} of obj: the length of a list or string, 0 or 1 for a null or other shape,
    None for the rest (links too: reading a PropertyLinkSubList that holds a deleted object kills
    FreeCAD 0.20). Not the labels, made unique when objects are imported into another document."""
    sizes = {}
    for name in set(obj.PropertiesList) - {"Label", "Label2"}:
        type_id = obj.getTypeIdOfProperty(name)
        if type_id.startswith("App::PropertyLink"):
            sizes[name] = None
        elif type_id == "Part::PropertyPartShape":
            sizes[name] = 0 if getattr(obj, name).isNull() else 1
        elif type_id.endswith("List") or type_id == "App::PropertyString":
            sizes[name] = len(getattr(obj, name))
        else:
            sizes[name] = None
    return sizes


class Proxy:
    """Base of the feature proxies. The document stores the type name and the size of each
    property (property_sizes); everything else is a property, and caches are rebuilt after
    loading. A property that comes back from the file missing or of another size is reported: a
    list FreeCAD keeps in a member file of its own comes back empty, without an error, when the
    member is missing from the .FCStd, and an object cut off in Document.xml without its last
    properties. The recompute makes lost results again and refuses to run while an input is lost.
    A link that would make a dependency cycle is refused (FreeCAD 0.20 takes one, and every
    recompute then runs the objects on it again in two passes and leaves one touched, without an
    error), and so is a list assigned to an enumeration (add_enumeration)."""

    Type = None

    def __init__(self, obj):
        self._object = obj
        obj.Proxy = self
        self.setup(obj)

    def setup(self, obj):
        raise NotImplementedError

    def onDocumentRestored(self, obj):
        self._object = obj
        saved = getattr(self, "_saved_sizes", None) or {}
        restored = property_sizes(obj)
        lost = {name: size for name, size in saved.items() if name not in restored or restored[name] != size}
        self.setup(obj)  # add_enumeration puts back choices the file changed
        self._saved_enumerations = None
        self.attach_view_provider(obj)
        if lost:
            self.report_losses(obj, lost, restored)

    def report_losses(self, obj, lost, restored):
        """Says what came back from the file lost and keeps the names for mustExecute and execute."""
        import FreeCAD

        def loss(name):
            if name not in restored:
                return "{} (missing)".format(name)
            if obj.getTypeIdOfProperty(name) == "Part::PropertyPartShape":
                return "{} (empty)".format(name)
            return "{} ({} of its {} values)".format(name, restored[name], lost[name])

        self._lost = getattr(self, "_lost", set()) | set(lost)
        inputs = self.lost_inputs(obj)
        advice = ("set {} again or open an intact copy: {} does not recompute until then".format(
            ", ".join(inputs), obj.Label) if inputs else "a recompute makes them again")
        FreeCAD.Console.PrintError("BVMesh: {} came back from the file without {} (the file is truncated or damaged); "
                                   "{}\n".format(obj.Label, ", ".join(loss(name) for name in sorted(lost)), advice))

    def lost_inputs(self, obj):
        return sorted(name for name in getattr(self, "_lost", ()) if name != "Shape"
                      and obj.getGroupOfProperty(name) != "Result" and "ReadOnly" not in obj.getEditorMode(name))

    def mustExecute(self, obj):
        # What a restore lost: FreeCAD purges a touch made while restoring.
        return bool(getattr(self, "_lost", None))

    @staticmethod
    def attach_view_provider(obj):
        """In the GUI, gives obj BVMesh's view provider unless it has one (a document written
        headless, e.g. by the main job, has none)."""
        import FreeCAD

        if FreeCAD.GuiUp and obj.ViewObject is not None and obj.ViewObject.Proxy is None:
            from bvmesh.gui import view_providers

            view_providers.attach(obj)
            # A headless document has no view state (the GUI opens its objects hidden): show the
            # ones its writer named.
            shown = obj.Document.Meta.get(VISIBLE_ON_OPEN)
            if shown is not None:
                obj.ViewObject.Visibility = obj.Name in shown.split()
                view_providers.fit_view_once(obj.Document)

    def add_enumeration(self, obj, name, group, doc, choices, default):
        """Adds enumeration property `name` with the feature's own `choices`, set to `default`,
        unless it exists, and keeps those choices. In FreeCAD, assigning a list to an enumeration
        (`obj.Method = ["bspline"]`) replaces its choices instead of setting its value; onChanged
        puts them back, with the value the property had, and says so in the Report view. On a
        restored object (setup from onDocumentRestored), choices the file changed are put back,
        with the value saved with the proxy (by name, FreeCAD keeps an index into the choices), else
        the restored one if it is one of them: an error names what came back. Choices that are
        some of the feature's own are those of an older version, put back without a word. A value
        that cannot be told is set to `default` and the object refuses to recompute until it is
        set again, as an input lost from the file."""
        choices = list(choices)
        if not hasattr(self, "_choices"):
            self._choices = {}
        if name not in obj.PropertiesList:
            obj.addProperty("App::PropertyEnumeration", name, group, doc)
            setattr(obj, name, choices)
            setattr(obj, name, default)
            self._choices[name] = (choices, default)
            return
        self._choices[name] = (choices, default)
        given, value = list(obj.getEnumerationsOfProperty(name)), getattr(obj, name)
        saved = (getattr(self, "_saved_enumerations", None) or {}).get(name)
        kept = saved if saved in choices else value if value in choices else None
        if given == choices and kept is not None and value == kept:
            return
        self._put_back_choices(obj, name, choices, default if kept is None else kept)
        if kept is not None and value == kept and set(given) <= set(choices):
            return
        import FreeCAD

        told = ["the choices " + describe_choices(given)] if given != choices else []
        if value != kept:
            told.append("no value" if value is None else "the value {}".format(value))
        message = "BVMesh: {}.{} came back from the file with {} (the file is damaged or was edited): its own " \
            "choices {} are put back".format(obj.Label, name, " and ".join(told), ", ".join(choices))
        if kept is None:
            self._lost = getattr(self, "_lost", set()) | {name}
            message += (", but the value it held is lost: it is {} until it is set again, and {} does not recompute "
                        "until then".format(default, obj.Label))
        else:
            message += ", with the value {}{}".format(kept, " saved with the object" if kept != value else "")
        FreeCAD.Console.PrintError(message + "\n")

    def _put_back_choices(self, obj, name, choices, value):
        putting_back, self._putting_back = getattr(self, "_putting_back", False), True
        try:
            setattr(obj, name, choices)
            setattr(obj, name, value)
        finally:
            self._putting_back = putting_back

    def onBeforeChange(self, obj, prop):
        # The value onChanged puts back: an enumeration's, a link's. PropertyLink only: reading a
        # PropertyLinkSubList that holds a deleted object kills FreeCAD 0.20 (those are checked by
        # the API and on recompute).
        if getattr(self, "_putting_back", False):
            return
        if prop in getattr(self, "_choices", {}):
            self._choice_before = (prop, getattr(obj, prop))
        elif obj.getTypeIdOfProperty(prop) == "App::PropertyLink":
            self._link_before = (prop, getattr(obj, prop))

    def onChanged(self, obj, prop):
        if getattr(self, "_putting_back", False):
            return
        if prop in getattr(self, "_choices", {}) and self._refuse_new_choices(obj, prop):
            return
        getattr(self, "_lost", set()).discard(prop)
        before, self._link_before = getattr(self, "_link_before", None), None
        if before is None or before[0] != prop or obj.Document.Restoring:
            return
        linked = getattr(obj, prop)
        path = None if linked is None else link_path(linked, obj)
        if path is None:
            return
        previous = before[1]
        self._putting_back = True
        try:
            setattr(obj, prop, previous)
        finally:
            self._putting_back = False
        import FreeCAD

        FreeCAD.Console.PrintError(
            "BVMesh: {}.{} cannot link {}, which depends on it ({}): a dependency cycle; {} is kept\n".format(
                obj.Label, prop, linked.Label, describe_path(path), previous.Label if previous else "no link"))

    def _refuse_new_choices(self, obj, prop):
        """Puts back the feature's own choices of enumeration `prop` when a change replaced them,
        with its value before the change (else the one it has now, or the default)."""
        before, self._choice_before = getattr(self, "_choice_before", None), None
        if obj.Document.Restoring:
            return False
        choices, default = self._choices[prop]
        given = list(obj.getEnumerationsOfProperty(prop))
        if given == choices:
            return False
        previous = before[1] if before is not None and before[0] == prop else None
        current = getattr(obj, prop)
        value = previous if previous in choices else current if current in choices else default
        self._put_back_choices(obj, prop, choices, value)
        import FreeCAD

        message = ("{}.{} takes one of {} as its value; a list would replace these choices (given: {}), refused: its "
                   "choices are kept and its value stays {}".format(obj.Label, prop, ", ".join(choices),
                                                                     describe_choices(given), value))
        FreeCAD.Console.PrintError("BVMesh: {}\n".format(message))
        if getattr(self, "refused", None) is not None:  # the API raises it (bvmesh.api._refusing)
            self.refused.append(message)
        return True

    def execute(self, obj):
        # FreeCAD only prints a failed recompute; keep the message for the API to raise.
        self.error = ""
        try:
            lost = self.lost_inputs(obj)
            if lost:
                raise ValueError("{} of {} came back from the file lost (the file is truncated or damaged): set them "
                                 "again or open an intact copy".format(", ".join(lost), obj.Label))
            cycle = link_path(obj, obj)
            if cycle is not None:
                raise ValueError("a dependency cycle: {} (each uses the next); link one of them to an object that "
                                 "does not depend on {}".format(describe_path(cycle), obj.Label))
            self.compute(obj)
            self._lost = set()
        except Exception as error:
            self.error = "{}: {}".format(type(error).__name__, error)
            raise

    def compute(self, obj):
        raise NotImplementedError

    def __getstate__(self):
        try:
            obj = self._object
            # The enumerations' values by name: the file keeps an index into their choices.
            return {"type": self.Type, "sizes": property_sizes(obj),
                    "enumerations": {name: getattr(obj, name) for name in getattr(self, "_choices", {})
                                     if name in obj.PropertiesList}}
        except (AttributeError, ReferenceError):  # no object yet, or a deleted one
            return self.Type

    def __setstate__(self, state):
        # A document saved before the sizes were kept stores the type name alone.
        self._saved_sizes = state.get("sizes") if isinstance(state, dict) else None
        self._saved_enumerations = state.get("enumerations") if isinstance(state, dict) else None
        return None

    # FreeCAD 0.20 looks for these names.
    dumps = __getstate__
    loads = __setstate__


class RecomputedProxy(Proxy):
    """A proxy whose result (blocks, a grid) lives in memory, not in the document: make(obj) builds
    it from the inputs that key(obj) identifies, deterministically, and obj.Digest keeps
    digest_of(result), so that a result made again after loading is checked against the saved one."""

    what = "result"

    def key(self, obj):
        raise NotImplementedError

    def make(self, obj):
        raise NotImplementedError

    def digest_of(self, result):
        raise NotImplementedError

    def result(self, obj):
        """The result in memory, else made again, which must give the saved digest."""
        key = self.key(obj)
        if getattr(self, "_result", None) is None or self._result_key != key:
            made = self.make(obj)
            if obj.Digest and self.digest_of(made) != obj.Digest:
                raise RuntimeError("{}: the {} made again differs from the saved one (digest {}); recompute the "
                                   "object".format(obj.Label, self.what, obj.Digest))
            self._result, self._result_key = made, key
        return self._result

    def fresh_result(self, obj):
        """(result, made) for a recompute: the result in memory when the inputs are unchanged (a
        display toggle), else a new one whose digest is stored."""
        key = self.key(obj)
        if getattr(self, "_result", None) is not None and self._result_key == key:
            return self._result, False
        self._result = None
        made = self.make(obj)
        obj.Digest = self.digest_of(made)
        self._result, self._result_key = made, key
        return made, True


def is_type(obj, type_name):
    """True when `obj` is a BVMesh object of the given proxy Type."""
    return getattr(getattr(obj, "Proxy", None), "Type", None) == type_name


class WorkCancelled(RuntimeError):
    """A long computation was cancelled: the recompute fails and the caller restores the document."""


_work_runner = None


@contextlib.contextmanager
def work_runner(runner):
    """Makes run_work call `runner(description, work) -> result` while the block runs (the GUI
    runs the work in a thread with a progress dialog; the macro line stays the plain API call)."""
    global _work_runner
    previous, _work_runner = _work_runner, runner
    try:
        yield
    finally:
        _work_runner = previous


def run_work(description, work):
    """work() directly (scripts, freecadcmd), or through the runner set by work_runner."""
    return work() if _work_runner is None else _work_runner(description, work)
