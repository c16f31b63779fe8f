"""Document glue of the HapticGrasp workbench.

The servo thread runs in the C++ core; the GUI thread (a QTimer, 30-60 Hz) calls
HapticSession.tick(), which reads a lock-free snapshot and moves the grasped part's
Placement. Only this thread touches the document. Lengths cross into the core in mm;
the core converts them once (freecad_boundary.cpp).

Undo: one transaction per manipulation, "Haptic move <label>", opened from tick() when
the grasp lifts the part (GRASP -> MANIPULATE) and committed when it is released. A
release from GRASP changes nothing. A device fault during a manipulation aborts the
transaction, puts the part back and says why in the report view.
"""
import math

import FreeCAD as App

try:
    from . import _hapticgrasp as core
except ImportError:  # the Mod folder itself is on sys.path (FreeCAD adds it)
    import _hapticgrasp as core

DEFAULT_DENSITY_KG_M3 = 1000.0
DENSITY_PROPERTY = "HapticDensity"   # kg/m^3, per part (App::PropertyFloat)
HOLDING = ("GRASP", "MANIPULATE")

# Force parameters (SI), set in the preferences page "Haptic Grasp" and read at start().
PARAMETER_PATH = "User parameter:BaseApp/Preferences/Mod/HapticGrasp"
PARAMETER_KEYS = ("K_c", "B_c", "K_g", "B_g", "d_h", "K_ox", "K_oe")


def default_parameters():
    """The core's defaults: the paper's K_c 130, B_c 100, K_g 1000, B_g 800; d_h, K_ox, K_oe
    as GraspParameters chose them."""
    return core.Session().parameters()


def stored_parameters():
    """The force parameters in the user's preferences (the defaults where none is stored)."""
    group = App.ParamGet(PARAMETER_PATH)
    defaults = default_parameters()
    return {key: group.GetFloat(key, defaults[key]) for key in PARAMETER_KEYS}


def store_parameters(values):
    """Writes force parameters to the user's preferences (not validated here: start() does)."""
    group = App.ParamGet(PARAMETER_PATH)
    for key, value in values.items():
        if key not in PARAMETER_KEYS:
            raise ValueError("unknown grasp parameter %s" % key)
        group.SetFloat(key, float(value))


def _warn(messages, text):
    messages.append(text)
    App.Console.PrintWarning("HapticGrasp: " + text + "\n")


def _error(messages, text):
    messages.append(text)
    App.Console.PrintError("HapticGrasp: " + text + "\n")


def placement_numbers(placement):
    """A FreeCAD Placement as the core takes it: ((x, y, z) mm, (qx, qy, qz, qw))."""
    b = placement.Base
    return (b.x, b.y, b.z), tuple(placement.Rotation.Q)


def same_placement(a, b, tol=1e-9):
    """Placements equal within tol (mm for the base; FreeCAD 0.20 has no Placement.isSame)."""
    return (a.Base - b.Base).Length <= tol and a.Rotation.isSame(b.Rotation, tol)


def to_placement(numbers):
    (x, y, z), (qx, qy, qz, qw) = numbers
    return App.Placement(App.Vector(x, y, z), App.Rotation(qx, qy, qz, qw))


def shape_brep(shape):
    """BREP text of the shape without its Placement (the Placement goes separately)."""
    local = shape.copy()
    local.Placement = App.Placement()
    return local.exportBrepToString()


def collect_solids(doc, messages):
    """Visible objects with a solid shape; anything else with a shape is skipped with one
    report-view line."""
    found = []
    for obj in doc.Objects:
        shape = getattr(obj, "Shape", None)
        if shape is None or not getattr(obj, "Visibility", True):
            continue
        if shape.isNull():
            _warn(messages, "skipping %s: empty shape" % obj.Label)
            continue
        kinds = {s.ShapeType for s in shape.childShapes()} if shape.ShapeType == "Compound" else {shape.ShapeType}
        if shape.ShapeType not in ("Solid", "CompSolid") and kinds != {"Solid"}:
            _warn(messages, "skipping %s: not a solid (%s), it cannot be grasped" % (obj.Label, shape.ShapeType))
            continue
        found.append(obj)
    return found


class HapticSession:
    """One session: the visible solids of `doc`, a device, the servo thread."""

    def __init__(self, doc, default_density=DEFAULT_DENSITY_KG_M3):
        self.doc = doc
        self.default_density = default_density
        self.messages = []        # what was said in the report view, for tests and the panel
        self.objects = []         # document objects, in the core's part order
        self.core = core.Session()
        self.state = "FREE"
        self.active = None        # index of the part being manipulated (transaction open)
        self.original = None      # its Placement before the manipulation
        self.moves = 0            # committed manipulations
        self.aborted = 0
        self.fault = "none"
        self._script = None       # (keys, frame Placement, pivot Vector) of a scripted hand
        self._hand = None         # the last set_hand() (index, thumb, wrist) in mm
        self._device_hand = False  # a HID device: the hand comes from the snapshot
        for obj in collect_solids(doc, self.messages):
            density = getattr(obj, DENSITY_PROPERTY, None) or default_density
            base, quaternion = placement_numbers(obj.Placement)
            try:
                self.core.add_part(obj.Label, shape_brep(obj.Shape), base, quaternion, density=density)
            except ValueError as e:   # GeometryError: open shells, self-intersections...
                _warn(self.messages, "skipping %s: %s" % (obj.Label, e))
                continue
            self.objects.append(obj)

    # --- device -----------------------------------------------------------------------
    def use_hand_script(self, keys, frame=None, pivot=None):
        """A scripted hand: keys (t_s, index_mm, thumb_mm, wrist_mm, shift_mm, turn_rad),
        `frame` a Placement of the script's frame; turns are about the vertical through
        `pivot` (a Vector, mm; default the frame's origin)."""
        base, quaternion = placement_numbers(frame or App.Placement())
        pivot_mm = None if pivot is None else (pivot.x, pivot.y, pivot.z)
        self.core.set_hand_script(keys, base, quaternion, pivot_mm)
        frame = App.Placement(frame or App.Placement())
        self._script = (list(keys), frame, App.Vector(pivot) if pivot is not None else App.Vector(frame.Base))
        self._hand = None
        self._device_hand = False

    def use_hand_input(self, hold_s=0.5):
        """A hand fed with set_hand() (the GUI, a script); it counts as silent hold_s after
        the last set_hand(), and the watchdog then faults the session."""
        self.core.use_hand_input(hold_s)
        self._script = None
        self._device_hand = False

    def use_spacemouse(self, path="", start=None, open_mm=80.0, closed_mm=0.0):
        """A SpaceMouse (path "": the first attached), opened now: its grip centre starts at
        `start` (a Vector, mm), opens to open_mm; button 1 pinches to closed_mm, button 2
        opens. Input only (no forces displayed). Raises core.DeviceError (a RuntimeError)
        with what to do when none is attached or it cannot be opened; the session's device
        is then unchanged."""
        start_mm = (0.0, 0.0, 0.0) if start is None else (start[0], start[1], start[2])
        self.core.use_spacemouse(path, start_mm, float(open_mm), float(closed_mm))
        self._script, self._hand, self._device_hand = None, None, True

    def use_hid(self, layout, path="", origin=None):
        """The HID device the JSON `layout` file describes (path "": the first attached one
        it matches), its frame's origin at `origin` (a Vector, mm). Raises core.LayoutError
        (a ValueError) for a bad layout, core.DeviceError as use_spacemouse()."""
        origin_mm = (0.0, 0.0, 0.0) if origin is None else (origin[0], origin[1], origin[2])
        self.core.use_hid(layout, path, origin_mm)
        self._script, self._hand, self._device_hand = None, None, True

    def set_hand(self, index_mm, thumb_mm, wrist_mm):
        """The hand now, document coordinates (mm); lock-free, cheap."""
        self.core.set_hand(tuple(index_mm), tuple(thumb_mm), tuple(wrist_mm))
        self._hand = tuple(App.Vector(*p) for p in (index_mm, thumb_mm, wrist_mm))

    def hand_at(self, t):
        """The device's hand (index, thumb, wrist: Vectors, mm, document coordinates) at
        servo time t: the scripted hand evaluated like the core's HandScript::at (linear
        between keys, turn about the vertical through the pivot), or the last set_hand();
        None before any hand is known. The core's snapshot does not carry it."""
        if self._script is None:
            return self._hand
        keys, frame, pivot = self._script
        if not keys:
            return None
        after = next((i for i, k in enumerate(keys) if t < k[0]), len(keys))
        a = keys[0] if after == 0 else keys[after - 1]
        b = keys[-1] if after == len(keys) else keys[after]
        u = min(1.0, max(0.0, (t - a[0]) / (b[0] - a[0]))) if b[0] > a[0] else 0.0

        def mix(p, q):
            return App.Vector(*p) * (1 - u) + App.Vector(*q) * u

        turn = App.Rotation(App.Vector(0, 0, 1), math.degrees((1 - u) * a[5] + u * b[5]))
        shift = mix(a[4], b[4])

        def place(local):
            return pivot + turn.multVec(frame.multVec(local) - pivot) + shift

        return tuple(place(mix(a[i], b[i])) for i in (1, 2, 3))

    # --- servo thread -----------------------------------------------------------------
    def start(self, rate_hz=1000.0, realtime=False, parameters=None):
        """Starts the servo thread with the force parameters of the preferences (or
        `parameters`, a dict in SI). A bad value raises ValueError naming the key."""
        if not self.objects:
            raise RuntimeError("no solid to grasp in %s" % self.doc.Label)
        self.parameters = stored_parameters() if parameters is None else dict(parameters)
        self.core.set_parameters(self.parameters)
        self.core.start(rate_hz, realtime)

    def stop(self):
        """Stops the servo thread; a manipulation still open is committed where it is."""
        self.core.stop()
        if self.active is not None:
            self._apply(self.core.snapshot())
            self._commit()

    def cancel(self):
        """Esc: stops the servo thread; a manipulation still open is aborted (no undo
        entry, the part back where it was) and the report view says "cancelled"."""
        self.core.stop()
        if self.active is not None:
            self._abort("cancelled", _warn)
        else:
            _warn(self.messages, "cancelled, haptics stopped (nothing was being moved)")

    @property
    def running(self):
        return self.core.running

    # --- the GUI timer ----------------------------------------------------------------
    def tick(self):
        """Read a snapshot and bring the document up to date. Returns the snapshot."""
        snap = self.core.snapshot()
        if self._device_hand and snap["tick"] > 0:   # a HID device: the hand it last read
            self._hand = tuple(App.Vector(*p) for p in snap["hand"])
        if snap["fault"] != "none":
            if self.fault == "none":
                self._on_fault(snap)
            self.fault = snap["fault"]
            self.state = snap["state"]
            return snap
        self.fault = "none"
        state, grasped = snap["state"], snap["grasped"]
        events = set(snap["event_names"])
        if self.active is not None:
            self._apply(snap)
            if state != "MANIPULATE" or grasped != self.active or "release" in events:
                self._commit()
        if self.active is None and state == "MANIPULATE" and 0 <= grasped < len(self.objects):
            self._begin(grasped)
            self._apply(snap)
        elif self.active is None and {"lift", "release"} <= events:
            # A whole manipulation between two ticks: move what moved, one step each.
            for index, obj in enumerate(self.objects):
                if not same_placement(to_placement(snap["placements"][index]), obj.Placement):
                    self._begin(index)
                    self._apply(snap)
                    self._commit()
        self.state = state
        return snap

    # --- internals --------------------------------------------------------------------
    def _begin(self, index):
        obj = self.objects[index]
        self.active = index
        self.original = App.Placement(obj.Placement)
        self.doc.openTransaction("Haptic move %s" % obj.Label)

    def _apply(self, snap):
        obj = self.objects[self.active]
        placement = to_placement(snap["placements"][self.active])
        if not same_placement(placement, obj.Placement):
            obj.Placement = placement

    def _commit(self):
        self.doc.commitTransaction()
        self.active = None
        self.original = None
        self.moves += 1

    def _on_fault(self, snap):
        # The core reset the grasp (every part back at its start pose): parts moved earlier
        # in this session would no longer match the document, so the session ends here.
        self.core.stop()
        self._abort("device fault (%s), haptics stopped" % snap["fault"], _error)

    def _abort(self, why, say):
        """Aborts the open manipulation (if any): its transaction, the part back."""
        if self.active is not None:
            obj = self.objects[self.active]
            self.doc.abortTransaction()
            if not same_placement(obj.Placement, self.original):  # undo off: put it back ourselves
                obj.Placement = self.original
            self.active = None
            self.original = None
            self.aborted += 1
            say(self.messages, "%s: move of %s aborted, the part is back where it was" % (why, obj.Label))
        else:
            say(self.messages, "%s: the grasp was reset" % why)


def layout_dirs():
    """Where HID layouts (*.json) are looked for: the package's devices/ folder, then the
    user's <FreeCAD user data>/HapticGrasp/devices/."""
    import os
    here = os.path.dirname(os.path.realpath(core.__file__))
    return [os.path.join(here, "devices"), os.path.join(App.getUserAppDataDir(), "HapticGrasp", "devices")]


def list_devices():
    """The HID devices attached, each a dict (path, vendor_id, product_id, product,
    manufacturer, backend "spacemouse" | "layout" | "none", model, layout file), and what
    went wrong, one line each (a layout file that did not load, an enumeration that
    failed): (devices, problems). Never raises."""
    try:
        listing = core.list_devices(layout_dirs())
    except Exception as e:   # hidapi could not start
        return [], ["HID enumeration failed: %s" % e]
    return listing["devices"], ["layout not loaded: %s" % e for e in listing["layout_errors"]]


def demo_script(obj, lift_mm=50.0, move_mm=(0.0, 100.0, 0.0), lift=True, turn_rad=0.0):
    """A scripted hand for `obj` (document coordinates): fingertips come in along x on
    either side of its bounding box centre, grasp, then (lift=True) lift by lift_mm, carry
    by move_mm while turning it by turn_rad about the vertical through its centre, put the
    part down and release, or (lift=False) open again without lifting.
    Once lifted (MANIPULATE) the part follows the midpoint of the fingertips rigidly, so it
    ends displaced by move_mm (plus the fraction of a millimetre the midpoint moved while
    the fingers closed). Returns (keys, frame Placement)."""
    box = obj.Shape.BoundBox
    half = 0.5 * box.XLength
    open_, inside = half + 20.0, half - 0.5
    squeezed = inside - 0.5
    mx, my, mz = move_mm
    keys = []

    def key(t, index, thumb, shift, turn=0.0):
        keys.append((t, (index, 0.0, 0.0), (-thumb, 0.0, 0.0), (0.0, 0.0, 100.0), shift, turn))

    still = (0.0, 0.0, 0.0)
    key(0.0, open_, open_, still)
    key(0.1, open_, open_, still)
    key(0.3, inside, open_, still)        # index contact
    key(0.5, inside, inside, still)       # thumb contact: GRASP
    key(0.6, squeezed, squeezed, still)
    if lift:
        key(1.0, squeezed, squeezed, (0.0, 0.0, lift_mm))         # springs carry the weight: MANIPULATE
        key(1.4, squeezed, squeezed, (mx, my, mz + lift_mm), turn_rad)  # carry and turn
        key(1.7, squeezed, squeezed, (mx, my, mz), turn_rad)            # put down
        key(1.9, squeezed, squeezed, (mx, my, mz), turn_rad)
        key(2.1, open_, open_, (mx, my, mz), turn_rad)                  # release
        key(2.3, open_, open_, (mx, my, mz + 20.0), turn_rad)
    else:
        key(1.0, squeezed, squeezed, still)
        key(1.2, open_, open_, still)                             # release from GRASP
        key(1.4, open_, open_, still)
    return keys, App.Placement(box.Center, App.Rotation())
