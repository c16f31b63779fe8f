"""Document glue of the HapticGrasp workbench.

The servo thread runs in the C++ core; the GUI thread (a QTimer, 30-60 Hz) calls
HapticSession.tick(), which reads a lock-free snapshot and moves the grasped part's
placement (PartRef: the part's own object, or the link instance it is shown through).
Only this thread touches the document. Lengths cross into the core in mm;
the core converts them once (freecad_boundary.cpp).

Undo: one transaction per manipulation, "Haptic move <label>", opened from tick() when
the grasp lifts the part (GRASP -> MANIPULATE) and committed when it is released. A
release from GRASP changes nothing. A device fault during a manipulation aborts the
transaction, puts the part back and says why in the report view.
"""
import math
import os
import time

import FreeCAD as App
import Part

from . import _hapticgrasp as core

DEFAULT_DENSITY_KG_M3 = 1000.0
DENSITY_PROPERTY = "HapticDensity"   # kg/m^3, per part (App::PropertyFloat)
GRASPABLE_PROPERTY = "HapticGraspable"   # App::PropertyBool; see collect_solids()
HOLDING = ("GRASP", "MANIPULATE")
SPLIT_COMMAND_PATH = "HapticGrasp > Split into solids"   # gui.py's HapticGrasp_SplitSolids, as the menu shows it

# Force parameters (SI), set in the preferences page "Haptic Grasp" and read at start().
PARAMETER_PATH = "User parameter:BaseApp/Preferences/Mod/HapticGrasp"
# The two-finger method's force laws [MH], then the multi-finger method's springs k and k_d,
# friction mu and distribution weights gamma1..3 [RF eq 19] (core.Session.parameters()).
PARAMETER_KEYS = ("K_c", "B_c", "K_g", "B_g", "d_h", "K_ox", "K_oe", "k", "k_d", "mu", "gamma1", "gamma2", "gamma3")
# The grasp method, stored beside them: the first paper's two-finger state machine, or the
# resultant-force paper's multi-finger method (as many fingertips as the device reads).
METHOD_KEY = "GraspMethod"
METHODS = ("two-finger", "multi-finger")


def stored_method():
    """The grasp method in the user's preferences ("two-finger" when none is stored)."""
    method = App.ParamGet(PARAMETER_PATH).GetString(METHOD_KEY, METHODS[0])
    return method if method in METHODS else METHODS[0]


def store_method(method):
    if method not in METHODS:
        raise ValueError("unknown grasp method %s (%s)" % (method, ", ".join(METHODS)))
    App.ParamGet(PARAMETER_PATH).SetString(METHOD_KEY, method)


# Recording (the preference "Record sessions", on by default): Start records the session
# into <document folder>/<document name>.reviews/<YYYY-MM-DD_HH-MM-SS>.mcap, or under
# UNSAVED_REVIEWS_DIR for a document never saved. Nothing in the document changes.
RECORD_KEY = "RecordSessions"
UNSAVED_REVIEWS_DIR = os.path.join("~", ".local", "share", "HapticGrasp", "reviews")


def stored_record():
    """Whether Start records the session (on when nothing is stored)."""
    return App.ParamGet(PARAMETER_PATH).GetBool(RECORD_KEY, True)


def store_record(on):
    App.ParamGet(PARAMETER_PATH).SetBool(RECORD_KEY, bool(on))


# Part-to-part contact (the preference "Carried parts meet the others", on by default): a
# carried part stops at the others and slides along them, and the hand feels it; off, it
# passes through them.
CONTACT_KEY = "PartContact"
# Deeper than this a put-down is said to be in interference: ten times the steady-contact
# penetration the contact keeps (0.05 mm at most, typically micrometres), so a part resting
# on another is never reported.
INTERFERENCE_MM = 0.5


def stored_contact():
    """Whether a carried part meets the others (on when nothing is stored)."""
    return App.ParamGet(PARAMETER_PATH).GetBool(CONTACT_KEY, True)


def store_contact(on):
    App.ParamGet(PARAMETER_PATH).SetBool(CONTACT_KEY, bool(on))


# The servo thread: its rate and whether it asks for real-time scheduling (SCHED_FIFO and
# locked memory). Without it a busy GUI costs the rate (measured under Xvfb: 820-857 Hz of
# 1 kHz with 4-5 ms of jitter), so both are on by default.
SERVO_RATE_KEY = "ServoRateHz"
REALTIME_KEY = "RealTime"
DEFAULT_SERVO_RATE_HZ = 2000.0


def stored_servo():
    """(rate Hz, real time) from the preferences: 2 kHz and real time when nothing is stored."""
    group = App.ParamGet(PARAMETER_PATH)
    return group.GetFloat(SERVO_RATE_KEY, DEFAULT_SERVO_RATE_HZ), group.GetBool(REALTIME_KEY, True)


def store_servo(rate_hz, realtime):
    if not 100.0 <= float(rate_hz) <= 10000.0:
        raise ValueError("servo rate %s Hz out of [100, 10000]" % rate_hz)
    group = App.ParamGet(PARAMETER_PATH)
    group.SetFloat(SERVO_RATE_KEY, float(rate_hz))
    group.SetBool(REALTIME_KEY, bool(realtime))


def recording_path(doc, now=None):
    """A new file for a session on `doc`, its folder created: <document folder>/<document
    name>.reviews/<YYYY-MM-DD_HH-MM-SS>.mcap (UNSAVED_REVIEWS_DIR for an unsaved document);
    "_2", "_3"... after the time when two starts fall in the same second."""
    if doc.FileName:
        name = os.path.splitext(os.path.basename(doc.FileName))[0]
        folder = os.path.join(os.path.dirname(doc.FileName), name + ".reviews")
    else:
        folder = os.path.expanduser(UNSAVED_REVIEWS_DIR)
    os.makedirs(folder, exist_ok=True)
    stamp = time.strftime("%Y-%m-%d_%H-%M-%S", time.localtime(now))
    path, n = os.path.join(folder, stamp + ".mcap"), 1
    while os.path.exists(path):
        n += 1
        path = os.path.join(folder, "%s_%d.mcap" % (stamp, n))
    return path


def recording_text(status):
    """The task panel's Recording field: file name, MB written, dropped records; the error;
    or "off" (status None)."""
    translate = App.Qt.translate   # the panel shows it
    if status is None:
        return translate("HapticGrasp", "off")
    if status["error"]:
        return translate("HapticGrasp", "error: %s") % status["error"]
    return translate("HapticGrasp", "%s, %.1f MB, %d dropped") % (os.path.basename(status["path"]),
                                                                  status["bytes"] / 1e6, status["dropped"])


def contact_text(contact, labels):
    """The task panel's Clearance field, from the snapshot's "contact" (None: nothing carried
    with contact): the distance from the carried part to the nearest other one and between
    which faces, "interference" with its depth, or why there is none to show. labels: the
    parts' labels, in scene order."""
    translate = App.Qt.translate
    if contact is None:
        return "-"
    if contact["part"] < 0:
        return translate("HapticGrasp", "none: the carried part has no contact shell yet (it passes through)")
    if not contact["exact"]:
        return translate("HapticGrasp", "no part near")
    other = contact["other_part"]
    name = labels[other] if 0 <= other < len(labels) else "?"
    faces = "Face%d / %s Face%d" % (contact["held_face"], name, contact["other_face"]) \
        if contact["held_face"] > 0 and contact["other_face"] > 0 else name
    if contact["clearance_mm"] < 0:
        return translate("HapticGrasp", "interference %.3f mm (%s)") % (-contact["clearance_mm"], faces)
    return translate("HapticGrasp", "%.3f mm (%s)") % (contact["clearance_mm"], faces)


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


_said_no_loader = False   # the report view hears it once per FreeCAD session


def _warn(messages, text):
    messages.append(text)
    App.Console.PrintWarning("HapticGrasp: " + text + "\n")


def _note(messages, text):
    messages.append(text)
    App.Console.PrintMessage("HapticGrasp: " + text + "\n")


def _error(messages, text):
    messages.append(text)
    App.Console.PrintError("HapticGrasp: " + text + "\n")


def _say_part(reports, label, info):
    """The report-view line for one built part: which back end answers it and why (a
    message for a sound B-rep, a warning when it was healed or needs a robust back end),
    then its load warnings (overlapping solids, faces sewn...), one line each."""
    line = "%s: %s" % (label, info["backend_reason"])
    sound = info["backend"] in ("exact", "analytic") and "healed" not in info["backend_reason"]
    reports.append(line)
    (App.Console.PrintMessage if sound else App.Console.PrintWarning)("HapticGrasp: " + line + "\n")
    for warning in info["warnings"]:
        line = "%s: %s" % (label, warning)
        reports.append(line)
        App.Console.PrintWarning("HapticGrasp: " + line + "\n")


def placement_numbers(placement):
    """A FreeCAD Placement as the core takes it: ((x, y, z) mm, (qx, qy, qz, qw))."""
    b = placement.Base
    return (b.x, b.y, b.z), tuple(placement.Rotation.Q)


def same_placement(a, b, tol=1e-9):
    """Placements equal within tol (mm for the base; FreeCAD 0.20 has no Placement.isSame).
    The rotations are compared as copies: in FreeCAD 0.20 Rotation.isSame is not a const
    method, so called on an object's obj.Placement.Rotation it writes the Placement back
    and marks the document modified (measured: a review preview that compared placements
    left the document "modified" with nothing changed)."""
    ra, rb = App.Rotation(*a.Rotation.Q), App.Rotation(*b.Rotation.Q)
    return (a.Base - b.Base).Length <= tol and ra.isSame(rb, tol)


def to_placement(numbers):
    (x, y, z), (qx, qy, qz, qw) = numbers
    return App.Placement(App.Vector(x, y, z), App.Rotation(qx, qy, qz, qw))


def shape_brep(shape):
    """BREP text of the shape without its Placement (the Placement goes separately)."""
    local = shape.copy()
    local.Placement = App.Placement()
    return local.exportBrepToString()


def global_placement(obj):
    """The object's placement in the document's global frame: its own Placement composed
    with those of the App::Part (and nested) containers it sits in."""
    if hasattr(obj, "getGlobalPlacement"):
        return obj.getGlobalPlacement()
    return App.Placement(obj.Placement)


def global_bound_box(part):
    """The bounding box in global coordinates of a PartRef, or of a document object (its
    Shape is in its container's frame)."""
    if isinstance(part, PartRef):
        return part.global_shape().BoundBox
    shape = part.Shape.copy(False)   # shares the geometry
    shape.Placement = global_placement(part)
    return shape.BoundBox


def is_graspable(obj):
    return bool(getattr(obj, GRASPABLE_PROPERTY, False))


def set_graspable(objects, on=True):
    """Marks (or unmarks) objects graspable: the boolean property HapticGraspable, added
    where missing. Once any object of a document is marked, only marked objects are handed
    to a session."""
    for obj in objects:
        if not hasattr(obj, GRASPABLE_PROPERTY):
            if not on:
                continue
            obj.addProperty("App::PropertyBool", GRASPABLE_PROPERTY, "Haptic",
                            "Handed to haptic sessions (once any part is marked, only marked parts are)")
        setattr(obj, GRASPABLE_PROPERTY, bool(on))


def _is_link(obj):
    """An App::Link (or an element of a link array): it shows another object's shape."""
    return obj.isDerivedFrom("App::Link") or obj.isDerivedFrom("App::LinkElement")


def is_part_candidate(obj):
    """Objects that may stand for a part (what "Mark graspable" takes): App::Links, and
    objects with a Shape that are not containers (App::Part: its Shape is the compound of
    its children, which are handed in themselves), nor the features inside a PartDesign
    Body (the Body stands for them)."""
    if _is_link(obj):
        return obj.getLinkedObject(True) is not None
    if getattr(obj, "Shape", None) is None:
        return False
    if obj.isDerivedFrom("App::Part") or obj.isDerivedFrom("PartDesign::Feature"):
        return False
    return True


# --- parts as the 3D view shows them -----------------------------------------------------
class PartRef:
    """One rigid part as the 3D view shows it: the object at the subname path `subname`
    from the top-level object `root` ("" when root is the part), as FreeCAD's own
    getSubObject / Part.getShape resolve it through containers and links.

    `obj` is the document object its placement is written to, and `index` the element
    when obj is a link array (else None). Without a link on the path obj is the part's
    own object. Through links it is the first link on the path (for an array, the link and
    the element's index): what lies beyond a link is shared by every link to the same
    target, so the link's placement is the only one this instance owns; a part inside a
    linked sub-assembly therefore moves its whole instance. `leaf` is the last object on
    the path; `source` the object whose shape the part shows (a link's linked object, else
    the leaf), the identity of its shape for sharing models (share_key)."""

    def __init__(self, root, subname, obj, index, parent, leaf, source, label):
        self.root = root
        self.subname = subname
        self.obj = obj
        self.index = index
        self.parent = parent   # path from root to what obj sits in (the array for an element); None: obj is root
        self.leaf = leaf
        self.source = source
        self.label = label

    def __repr__(self):
        return "<PartRef %s>" % self.label

    def global_shape(self):
        """The part's shape where the 3D view shows it (its Placement is the global one)."""
        return Part.getShape(self.root, self.subname, needSubElement=False, transform=True)

    def shape(self):
        """The part's shape in its own frame (no placement); shares the document's geometry."""
        shape = self.global_shape()
        shape.Placement = App.Placement()
        return shape

    def global_placement(self):
        return self.global_shape().Placement

    def placement(self):
        """obj's own placement: its Placement, or the array element's (the element
        object's Placement, or the entry of PlacementList when the elements are not shown
        as objects)."""
        if self.index is None:
            return App.Placement(self.obj.Placement)
        elements = self.obj.ElementList
        if elements:
            return App.Placement(elements[self.index].Placement)
        return App.Placement(self.obj.PlacementList[self.index])

    def set_placement(self, placement):
        if self.index is None:
            self.obj.Placement = placement
            return
        elements = self.obj.ElementList
        if elements:
            elements[self.index].Placement = placement
        else:
            placements = list(self.obj.PlacementList)
            placements[self.index] = placement
            self.obj.PlacementList = placements

    def frame(self):
        """(before, after) with global placement = before * placement() * after: `before`
        the placements above obj on the path (containers, links, the array), `after` from
        obj's frame to the shape's (a LinkTransform link's target Placement, the part's
        place inside a linked sub-assembly; identity for a plain object)."""
        before = App.Placement() if self.parent is None else self.root.getSubObject(self.parent, retType=3)
        after = before.multiply(self.placement()).inverse().multiply(self.global_placement())
        return before, after

    def set_global_placement(self, placement, frame=None):
        """Moves the part to `placement` (global) by writing obj's own placement; `frame`
        is a frame() taken earlier (a manipulation keeps one)."""
        before, after = frame or self.frame()
        self.set_placement(before.inverse().multiply(placement).multiply(after.inverse()))


def share_key(ref):
    """A string naming the part's shape source: equal for parts that show the same shape in
    their own frames (links to one target, instances of one linked sub-assembly), so that
    a model can be built once for them."""
    return "%s#%s" % (ref.source.Document.Name, ref.source.Name)


def _link_target(link):
    """What a link shows: its linked object, through further (non-array) links."""
    target = link.LinkedObject
    if isinstance(target, tuple):   # a link to sub-elements: (object, [names])
        target = target[0]
    if target is not None and _is_link(target) and not getattr(target, "ElementCount", 0):
        target = target.getLinkedObject(True)
    return target


def _children(obj):
    """(subname, object) of what obj shows as its children in the tree and the 3D view:
    an App::Part's, a group's, an App::LinkGroup's objects (FreeCAD's getSubObjects). A
    Body, a compound, a Draft link array show none: each is one part."""
    if obj.hasExtension("App::LinkExtension") and not _is_link(obj):   # e.g. Draft link arrays
        return []
    children = []
    for sub in obj.getSubObjects():
        child = obj.getSubObject(sub, retType=1)
        if child is not None:
            children.append((sub, child))
    return children


def _top_level(doc):
    """The document's objects that no other object shows as its child (in the tree's top
    level): the walk starts there. A link does not claim its target: a visible target at
    the top level is shown, and collected, as itself too."""
    claimed = set()
    for obj in doc.Objects:
        if _is_link(obj):
            continue
        for _sub, child in _children(obj):
            claimed.add(child)
        if obj.hasExtension("App::GroupExtension"):   # a Body's features
            claimed.update(obj.Group)
    return [o for o in doc.Objects if o not in claimed and not o.isDerivedFrom("App::LinkElement")]


def _scales(link, index=None):
    """Whether a link (or its array element `index`) scales or mirrors what it shows: its
    ScaleVector, the element's ScaleList entry or element object's ScaleVector."""
    def off(scale):
        return scale is not None and (App.Vector(scale) - App.Vector(1, 1, 1)).Length > 1e-12

    if off(getattr(link, "ScaleVector", None)):
        return True
    if index is None:
        return False
    scales = getattr(link, "ScaleList", [])
    elements = getattr(link, "ElementList", [])
    return (index < len(scales) and off(scales[index])) or \
        (index < len(elements) and off(getattr(elements[index], "ScaleVector", None)))


def _element_visible(parent, name, child):
    """Whether parent shows its child `name`: the parent's element visibility where it has
    one (App::LinkGroup, link arrays), else the child's Visibility."""
    shown = parent.isElementVisible(name)
    return bool(child.Visibility) if shown < 0 else bool(shown)


def _walk(root, found):
    """Appends (PartRef, shown, scaled) for every part under the top-level object `root`,
    depth first, hidden ones too (shown False: collect_solids() names marked parts hidden);
    scaled: a link on its path scales or mirrors it."""

    def label_of(prefix, obj, index=None):
        name = obj.Label if index is None else "%s[%d]" % (obj.Label, index)
        return name if prefix is None else prefix + "/" + name

    def visit(obj, sub, parent, shown, scaled, writer, label, depth):
        # obj is reached by `sub` from root; parent is the path to what holds it (None at
        # root). writer: (object, element index, its parent path) of the first link on the
        # path, None before one. label: the path's labels from the writer on, None before.
        if depth > 64:   # FreeCAD forbids cycles; this bounds a broken document
            return
        if _is_link(obj):
            target = _link_target(obj)
            if target is None:
                return
            count = getattr(obj, "ElementCount", 0) if obj.isDerivedFrom("App::Link") else 0
            for i in range(count):   # a link array: each element is an instance
                visit_target(obj, target, sub + "%d." % i, shown and obj.isElementVisible(str(i)) != 0,
                             scaled or _scales(obj, i), writer or (obj, i, sub), label_of(label, obj, i), depth)
            if not count:
                visit_target(obj, target, sub, shown, scaled or _scales(obj), writer or (obj, None, parent),
                             label_of(label, obj), depth)
            return
        here = None if label is None else label_of(label, obj)
        children = _children(obj)
        for name, child in children:
            visit(child, sub + name, sub, shown and _element_visible(obj, name[:-1], child), scaled, writer, here,
                  depth + 1)
        if not children:
            add(sub, parent, obj, obj, shown, scaled, writer, here)

    def visit_target(link, target, sub, shown, scaled, writer, label, depth):
        # What a link shows: the target's own Visibility does not count (the link shows it).
        children = [] if _is_link(target) else _children(target)
        for name, child in children:
            visit(child, sub + name, sub, shown and _element_visible(target, name[:-1], child), scaled, writer,
                  label, depth + 1)
        if not children:
            add(sub, None, link, target, shown, scaled, writer, label)

    def add(sub, parent, leaf, source, shown, scaled, writer, label):
        obj, index, parent = writer or (leaf, None, parent)
        found.append((PartRef(root, sub, obj, index, parent, leaf, source,
                              leaf.Label if label is None else label), shown, scaled))

    visit(root, "", None, bool(root.Visibility), False, None, None, 0)


def collect_solids(doc, messages):
    """The parts to hand to a session, as PartRefs: every part the 3D view shows, walked
    from the top-level objects through containers (App::Part, groups, App::LinkGroup) and
    links (a part shown through several links is one part per link instance, a link array
    one per element), or, once any object is marked graspable (HapticGraspable), only the
    parts whose object, leaf or source is marked. A hidden container hides its children;
    a link array's hidden elements are hidden. Anything else asked for that is not a
    solid is skipped with one report-view line; so is a marked object shown nowhere. An
    object holding several solids is one rigid part, and the report view says once how to
    split it (split_solids)."""
    walked = []
    for root in _top_level(doc):
        _walk(root, walked)
    marked = [o for o in doc.Objects if is_graspable(o)]

    def is_marked(ref):
        return any(is_graspable(o) for o in (ref.obj, ref.leaf, ref.source))

    found = []
    several = set()   # sources said to hold several solids
    for ref, shown, scaled in walked:
        if not shown or (marked and not is_marked(ref)):
            continue
        if getattr(ref.source, "Shape", None) is None:
            continue   # no geometry (an origin, a spreadsheet): not a part, nothing to say
        try:
            shape = ref.global_shape()
        except Exception as e:
            _warn(messages, "skipping %s: its shape cannot be read: %s" % (ref.label, e))
            continue
        if shape.isNull():
            _warn(messages, "skipping %s: empty shape" % ref.label)
            continue
        # Solids, nested in compounds as STEP assemblies read (one rigid part however many),
        # or shells the core closes into solids; the core refuses, with one line, what has
        # no closed shell. Sketches and sheets are not parts.
        if not shape.Solids and not shape.Shells:
            _warn(messages, "skipping %s: not a solid (%s), it cannot be grasped" % (ref.label, shape.ShapeType))
            continue
        if scaled:
            _warn(messages, "skipping %s: a link scales it, so it is not a rigid copy of its source" % ref.label)
            continue
        if len(shape.Solids) > 1 and ref.source not in several:
            several.add(ref.source)
            _note(messages, "%s holds %d solids, carried as one rigid part; %s makes each graspable"
                  % (ref.label, len(shape.Solids), SPLIT_COMMAND_PATH))
        found.append(ref)
    for obj in marked:
        if not any(obj in (r.obj, r.leaf, r.source) for r in found) and \
                any(obj in (r.obj, r.leaf, r.source) for r, shown, _scaled in walked if not shown):
            _warn(messages, "skipping %s: marked graspable but hidden" % obj.Label)
    _say_shared_instances(found, messages)
    return found


def _say_shared_instances(refs, messages):
    """One line per linked instance that holds several parts: a move writes the instance's
    link, so its other parts move with the one grasped."""
    held = {}
    for ref in refs:
        held.setdefault((ref.obj, ref.index), []).append(ref)
    for (obj, index), group in held.items():
        if len(group) > 1:
            name = obj.Label if index is None else "%s[%d]" % (obj.Label, index)
            _note(messages, "%s: its %d parts are one linked instance in the document, moving one moves them all"
                  % (name, len(group)))


def solid_count(obj):
    """How many solids obj's Shape holds (0 for an object without a Shape)."""
    shape = getattr(obj, "Shape", None)
    return 0 if shape is None else len(shape.Solids)


def split_solids(objects):
    """Splits each object whose shape holds several solids into one new Part::Feature per
    solid ("<label> solid N", in the same container, each solid where it was; the density
    and the graspable mark carried over), and hides the original (it is kept, unmarked).
    One transaction ("Split into solids"): one undo step. Returns the new objects."""
    objects = [o for o in objects if solid_count(o) > 1]
    if not objects:
        return []
    doc = objects[0].Document
    made = []
    doc.openTransaction("Split into solids")
    try:
        for obj in objects:
            made += _split(obj)
    except Exception:
        doc.abortTransaction()
        raise
    doc.commitTransaction()
    return made


def _split(obj):
    doc = obj.Document
    container = obj.getParentGroup() or obj.getParentGeoFeatureGroup()   # a folder, an App::Part
    groups = [g for g in obj.InList if g.isDerivedFrom("App::LinkGroup") and obj in g.ElementList]
    made = []
    for n, solid in enumerate(obj.Shape.Solids, 1):
        piece = doc.addObject("Part::Feature", obj.Name + "_solid")
        piece.Label = "%s solid %d" % (obj.Label, n)
        piece.Shape = solid   # in obj's container's frame: its Placement becomes the piece's
        for prop in (DENSITY_PROPERTY, GRASPABLE_PROPERTY):
            if hasattr(obj, prop):
                piece.addProperty(obj.getTypeIdOfProperty(prop), prop, "Haptic", obj.getDocumentationOfProperty(prop))
                setattr(piece, prop, getattr(obj, prop))
        made.append(piece)
    if container is not None:
        for piece in made:
            container.addObject(piece)
    for group in groups:
        group.ElementList = list(group.ElementList) + made
    if hasattr(obj, GRASPABLE_PROPERTY):
        setattr(obj, GRASPABLE_PROPERTY, False)
    obj.Visibility = False
    return made


# Cancelled ModelBuilds still finishing the part in progress. Dropping one waits for its
# worker (the destructor joins it), so they are kept here and dropped once finished: the GUI
# thread never waits for a cancelled build.
_DRAINING = []


def drain(build=None):
    """Cancels `build` (if given) and keeps it until finished; drops the finished ones."""
    if build is not None:
        build.cancel()
        _DRAINING.append(build)
    _DRAINING[:] = [b for b in _DRAINING if not b.progress()["finished"]]
    return len(_DRAINING)


def density_of(ref, default_density=DEFAULT_DENSITY_KG_M3):
    """kg/m^3: the HapticDensity of the part's object, else of its leaf or source (a link
    takes its target's), else the default."""
    for obj in (ref.obj, ref.leaf, ref.source):
        density = getattr(obj, DENSITY_PROPERTY, None)
        if density:
            return density
    return default_density


def part_request(ref, default_density=DEFAULT_DENSITY_KG_M3, shape=None):
    """What the core's ModelBuild takes for one part (a PartRef): (name, BREP text without
    the Placement, global base mm, quaternion, density kg/m^3). `shape`: its global_shape()
    if read already. GUI thread (reads the document)."""
    shape = ref.global_shape() if shape is None else shape
    base, quaternion = placement_numbers(shape.Placement)
    return (ref.label, shape_brep(shape), base, quaternion, density_of(ref, default_density))


class HapticSession:
    """One session: the visible solids of `doc`, a device, the servo thread."""

    def __init__(self, doc, default_density=DEFAULT_DENSITY_KG_M3, wait=True, scene=False):
        """Collects the parts. scene=True (the workbench's Start): nothing is built now;
        start() runs the servo at once on every part's bounding box and tick() hands the
        core each distinct shape (share_key) as the background build asks for it, nearest
        the hand first, within EXPORT_BUDGET_S per tick. Otherwise the models are built
        first on the core's worker thread (ModelBuild: OpenCASCADE checks and penetration
        models, no GIL held): wait=True (scripts, tests) blocks until built, the GIL
        released; wait=False returns at once: poll_build() from a timer, then start() once
        `ready`."""
        self.doc = doc
        self.default_density = default_density
        self.messages = []        # what was said in the report view, for tests and the panel
        self.part_reports = []    # the report view's lines about each built part: back end, why, warnings
        self.parts = []           # PartRefs, in the core's part order
        self.shapes = []          # per part: the shape its model was built from (TShape identity)
        self.rebuilds = {}        # part index -> (ModelBuild, Label) of a rebuild in flight
        self.rebuilt = []         # per part: models swapped in after an edit
        self.restarts = 0         # servo loops restarted to swap models in
        self.core = core.Session()
        self.state = "FREE"
        self.active = None        # index of the part being manipulated (transaction open)
        self._move_written = False      # the move has written a placement (its transaction exists)
        self._undo_counts = (0, 0)      # the document's (UndoCount, RedoCount) after its last write
        self.original = None      # its object's own placement before the manipulation (PartRef.placement())
        self.frame = None         # its PartRef.frame(): the placements around it, fixed meanwhile
        self.moves = 0            # committed manipulations
        self.last_contact = None  # the snapshot's "contact" while a part was last carried
        self.aborted = 0
        self.closed = False       # the document was closed under the session (it stopped)
        self.halted = False       # a part was deleted under the session: it stopped, no more writes
        self.fault = "none"
        self._script = None       # (keys, frame Placement, pivot Vector) of a scripted hand
        self._hand = None         # the last set_hand() (index, thumb, wrist) in mm
        self._device_hand = False  # a HID device or the arm: the hand comes from the snapshot
        self.target = None        # the simulated arm: the last target set_hand() gave (Vectors, mm)
        self.arm = None           # the simulated arm's resting hand (arm_rest()), when it is the device
        self.cancelled = False
        self.recording = None     # the recording's first file while one was asked for (start())
        self.record_reports = []  # the report view's lines about the recording (apart from messages)
        self._said_recorded = False
        self._candidates = collect_solids(doc, self.messages)
        self._requested = []   # (PartRef, the shape exported), in the build's request order
        self._next = 0         # candidates exported so far
        self.scene = scene
        self.build = None
        self._said_models = set()   # scene mode: models whose report line was said
        self.model_sources = {}     # scene mode: model -> "built", "memory", "disk", "rebuilt (why)"
        self._sweep = 0             # scene mode: the next part the edit watch looks at
        if scene:
            self.parts = list(self._candidates)
            self.shapes = [None] * len(self.parts)   # read as the sweep comes by
            self.rebuilt = [0] * len(self.parts)
        elif wait:
            self.build = core.ModelBuild([r for r in map(self._export, self._candidates) if r is not None])
            self._next = len(self._candidates)
            self.build.wait()
            self.poll_build()
        else:
            # The BREP export reads the document, so it runs here, on the GUI thread: a few
            # parts per poll_build() (EXPORT_BUDGET_S), never all at once.
            self.build = core.ModelBuild([], open=True)
            self._export_more()

    EXPORT_BUDGET_S = 0.015   # BREP export per poll_build() (~4 ms for 200 faces, ~45 ms for 1600)

    def _export(self, ref):
        """The core's request for a part, or None (named in the report view) if its shape
        cannot be exported."""
        try:
            shape = ref.global_shape()
            request = part_request(ref, self.default_density, shape)
        except Exception as e:
            _warn(self.messages, "skipping %s: its shape cannot be exported: %s" % (ref.label, e))
            return None
        self._requested.append((ref, shape))
        return request

    def _export_more(self):
        """Hands the next candidates to the open build, within EXPORT_BUDGET_S (at least one)."""
        import time
        start = time.monotonic()
        while self._next < len(self._candidates):
            request = self._export(self._candidates[self._next])
            self._next += 1
            if request is not None:
                self.build.add(request)
            if time.monotonic() - start > self.EXPORT_BUDGET_S:
                break
        if self._next == len(self._candidates):
            self.build.close()

    # --- scene mode -------------------------------------------------------------------
    def _scene_requests(self):
        """Per part: (name, share key, box min, box max in its own frame (mm), global base,
        quaternion, density). The boxes come straight from the shapes (no model)."""
        requests = []
        for ref in self.parts:
            shape = ref.global_shape()
            local = shape.copy(False)   # shares the geometry
            local.Placement = App.Placement()
            box = local.BoundBox
            base, quaternion = placement_numbers(shape.Placement)
            requests.append((ref.label, share_key(ref), (box.XMin, box.YMin, box.ZMin), (box.XMax, box.YMax, box.ZMax),
                             base, quaternion, density_of(ref, self.default_density)))
        return requests

    def feed_shapes(self, budget_s=None):
        """Scene mode, GUI timer: exports the shapes the background build asks for (nearest
        the hand first) within budget_s, and says once per model which back end answers it.
        Returns how many shapes were handed over."""
        import time
        budget_s = self.EXPORT_BUDGET_S if budget_s is None else budget_s
        start, fed = time.monotonic(), 0
        while time.monotonic() - start < budget_s:
            wanted = self.core.wanted_shapes(4)
            if not wanted:
                break
            for model in wanted:
                ref = self.parts[self.core.first_part_of_model(model)]
                try:
                    brep = shape_brep(ref.global_shape())
                except Exception as e:   # the part keeps its box
                    brep = ""
                    _warn(self.messages, "%s: its shape cannot be exported (%s): it is felt as its box" % (ref.label, e))
                self.core.provide_shape(model, brep)
                fed += 1
                if time.monotonic() - start >= budget_s:
                    break
        self._say_models()
        return fed

    def _say_models(self):
        status = self.core.scene_status()
        if status["built"] + status["failed"] == len(self._said_models):
            return
        for model in range(status["models"]):
            if model in self._said_models:
                continue
            info = self.core.model_info(model)
            if info["backend"] == "box" and not info["error"]:
                continue   # still waiting or building
            self._said_models.add(model)
            first = self.core.first_part_of_model(model)
            label = self.parts[first].label
            count = sum(1 for i in range(len(self.parts)) if self.core.model_of_part(i) == model)
            if count > 1:
                label += " (and %d more parts of the same shape)" % (count - 1)
            if info["source"] in ("memory", "disk"):
                info["backend_reason"] += " (checked before: from the model cache)"
            elif info["source"].startswith("rebuilt"):
                _warn(self.messages, "%s: its cached model was %s" % (label, info["source"]))
            _say_part(self.part_reports, label, info)
            self.model_sources[model] = info["source"]

    def scene_progress(self):
        """Scene mode: (parts answered by their own model, parts)."""
        status = self.core.scene_status()
        return status["exact_parts"], status["parts"]

    # --- model build ------------------------------------------------------------------
    @property
    def ready(self):
        """The models are built and in the core (scene mode: at once): start() may be called."""
        return self.build is None and not self.cancelled

    def build_progress(self):
        """(done, total, name of the part being built or "") of the initial build."""
        if self.build is None:
            n = len(self._candidates)
            return (n, n, "")
        p = self.build.progress()
        failed_exports = self._next - len(self._requested)
        return (p["done"] + failed_exports, len(self._candidates), p["current"])

    def poll_build(self):
        """GUI timer: True once the build is over (built, or cancelled). The first call that
        sees it finished adds the built parts to the core and names each part that could
        not be built in the report view; a cancelled build adds nothing."""
        if _DRAINING:
            drain()
        if self.build is None:
            return True
        if self._next < len(self._candidates):
            self._export_more()
        if not self.build.progress()["finished"]:
            return False
        build, self.build = self.build, None
        if self.cancelled or build.progress()["cancelled"]:
            self.cancelled = True
            return True
        for _request, name, error in build.errors():
            _warn(self.messages, "skipping %s: %s" % (name, error))
        for request, index in self.core.add_built(build):
            assert index == len(self.parts)
            ref, shape = self._requested[request]
            self.parts.append(ref)
            self.shapes.append(shape)
            self.rebuilt.append(0)
            _say_part(self.part_reports, ref.label, self.core.part_info(index))
        return True

    def cancel_build(self):
        """Cancels the initial build: no part is added, start() refuses. The worker
        finishes the part in progress in the background (see drain())."""
        build = self.build
        if build is None:
            return
        drain(build)
        self.cancelled = True
        self.build = None
        p = build.progress()
        _warn(self.messages, "model build cancelled (%d of %d parts built): no session" % (p["done"], p["total"]))

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
        self.arm = self.target = None

    def use_hand_input(self, hold_s=0.5):
        """A hand fed with set_hand() (the GUI, a script); it counts as silent hold_s after
        the last set_hand(), and the watchdog then faults the session."""
        self.core.use_hand_input(hold_s)
        self._script = None
        self._device_hand = False
        self.arm = self.target = None

    ARM_REST_ABOVE_MM = 30.0   # the arm's resting grip centre above the target part's top

    def use_simulated_arm(self, target=None, rest=None, grip_axis=None, hold_s=0.5):
        """The simulated master arm: set_hand() gives its simulated operator's target (the
        mouse-and-keyboard hand), the grasp sees the ARM's fingertips (the snapshot's hand)
        and the forces go to its joints. Placed so that its resting grip centre is `rest` (a
        Vector, mm), by default ARM_REST_ABOVE_MM above the top centre of `target` (a
        PartRef or a document object, global bounding box), with its grip axis (thumb -> index) along
        `grip_axis` (a horizontal Vector), by default the box's narrower horizontal side
        (y for the sample block). The hand opens to about 100 mm: a part is grasped across
        a side narrower than about 70 mm. Silent hold_s after the last set_hand().
        Returns the arm's resting hand: a dict of index, thumb, wrist, grip_axis (mm)."""
        box = global_bound_box(target) if target is not None else None
        if rest is None:
            if box is None:
                raise ValueError("use_simulated_arm: give a target part or a rest point")
            rest = App.Vector(box.Center.x, box.Center.y, box.ZMax + self.ARM_REST_ABOVE_MM)
        if grip_axis is None:
            grip_axis = (App.Vector(0, 1, 0) if box is None or box.YLength <= box.XLength
                         else App.Vector(1, 0, 0))
        self.core.use_simulated_arm((rest[0], rest[1], rest[2]), (grip_axis[0], grip_axis[1], grip_axis[2]),
                                    hold_s)
        self.arm = self.core.arm_rest()
        self._script, self._hand, self._device_hand = None, None, True
        self.target = None
        return self.arm

    def use_spacemouse(self, path="", start=None, open_mm=80.0, closed_mm=0.0):
        """A SpaceMouse (path "": the first attached), opened now: its grip centre starts at
        `start` (a Vector, mm), opens to open_mm; button 1 pinches to closed_mm, button 2
        opens. Input only (no forces displayed). Raises core.DeviceError (a RuntimeError)
        with what to do when none is attached or it cannot be opened; the session's device
        is then unchanged."""
        start_mm = (0.0, 0.0, 0.0) if start is None else (start[0], start[1], start[2])
        self.core.use_spacemouse(path, start_mm, float(open_mm), float(closed_mm))
        self._script, self._hand, self._device_hand = None, None, True
        self.arm = self.target = None

    def use_hid(self, layout, path="", origin=None):
        """The HID device the JSON `layout` file describes (path "": the first attached one
        it matches), its frame's origin at `origin` (a Vector, mm). Raises core.LayoutError
        (a ValueError) for a bad layout, core.DeviceError as use_spacemouse()."""
        origin_mm = (0.0, 0.0, 0.0) if origin is None else (origin[0], origin[1], origin[2])
        self.core.use_hid(layout, path, origin_mm)
        self._script, self._hand, self._device_hand = None, None, True
        self.arm = self.target = None

    def set_hand(self, index_mm, thumb_mm, wrist_mm):
        """The hand now, document coordinates (mm); lock-free, cheap. With the simulated
        arm this is the operator's target (`target`); the hand is then the arm's."""
        self.core.set_hand(tuple(index_mm), tuple(thumb_mm), tuple(wrist_mm))
        hand = tuple(App.Vector(*p) for p in (index_mm, thumb_mm, wrist_mm))
        if self.arm is not None:
            self.target = hand
        else:
            self._hand = hand

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
    def start(self, rate_hz=None, realtime=None, parameters=None, method=None, record=None, contact=None):
        """Starts the servo thread with the rate, real-time request, force parameters,
        grasp method and part-to-part contact of the preferences (or those given:
        `parameters` a dict in SI). A bad value raises ValueError naming the key. record:
        None follows the preference "Record sessions" (recording_path()), False records
        nothing, a str is the file to record to. Real time asked for and refused is said in
        the report view, with the fix."""
        stored_rate, stored_realtime = stored_servo()
        rate_hz = stored_rate if rate_hz is None else rate_hz
        realtime = stored_realtime if realtime is None else realtime
        if self.cancelled:
            raise RuntimeError("the model build was cancelled")
        if not self.poll_build():
            raise RuntimeError("the part models are still being built")
        if not self.parts:
            raise RuntimeError("no solid to grasp in %s" % self.doc.Label)
        self.parameters = stored_parameters() if parameters is None else dict(parameters)
        self.core.set_parameters(self.parameters)
        self.core.set_method(stored_method() if method is None else method)
        self.core.set_contact(stored_contact() if contact is None else contact)
        self._record_to(stored_record() if record is None else record)
        if self.scene:
            self.core.start_scene(self._scene_requests(), rate_hz, realtime)
            self.feed_shapes()
        else:
            self.core.start(rate_hz, realtime)
        self._say_servo()
        self._say_loader()
        self._say_recording()

    def servo_timing(self):
        """The core's servo_timing(): target_hz, achieved_hz, period_err_us {p50, p99, max},
        scheduler, memory_lock, realtime, advice."""
        return self.core.servo_timing()

    def _say_loader(self):
        """Once per FreeCAD session: parts load inside FreeCAD, not in the loader process."""
        global _said_no_loader
        status = core.loader()
        if not status["isolated"] and not _said_no_loader:
            _said_no_loader = True
            _warn(self.messages, "parts load inside FreeCAD (%s): a part that crashes OpenCASCADE "
                  "would take FreeCAD with it" % status["why"])

    def _say_servo(self):
        timing = self.core.servo_timing()
        if timing["advice"]:
            _warn(self.messages, "servo at %.0f Hz without real time: %s" % (timing["target_hz"], timing["advice"]))

    # --- recording ----------------------------------------------------------------------
    def _record_to(self, record):
        """Tells the core where to record (before it starts); a folder that cannot be made
        is said and haptics start without recording."""
        if not record:
            return
        try:
            path = record if isinstance(record, str) else recording_path(self.doc)
        except OSError as e:
            _warn(self.record_reports, "not recording: %s" % e)
            return
        self.core.record_to(path, self.doc.FileName or self.doc.Label)
        self.recording = path

    def _say_recording(self):
        if self.recording is None:
            return
        status = self.core.recording_status()
        if status["error"]:
            _warn(self.record_reports, "not recording: %s" % status["error"])
        else:
            _note(self.record_reports, "recording to %s" % self.recording)

    def _say_recorded(self):
        """The report view's line once the servo stopped: how long, where, how big."""
        if self.recording is None or self._said_recorded:
            return
        self._said_recorded = True
        status = self.core.recording_status()
        if not status["files"] or (status["error"] and not status["ticks"]):
            return   # never recorded: said at start
        line = "recorded %.1f s to %s (%.1f MB)" % (status["duration_s"], ", ".join(status["files"]),
                                                    status["bytes"] / 1e6)
        if status["dropped"]:
            line += ", %d servo ticks dropped" % status["dropped"]
        _note(self.record_reports, line)

    def recording_status(self):
        """The core's recording_status() dict, or None when this session does not record."""
        return None if self.recording is None else self.core.recording_status()

    def mark_note(self):
        """Where a note begun now belongs: (servo time, part under the hand), or None when
        not recording. Taken when the reviewer presses N, before the note is typed."""
        if self.recording is None or not self.core.recording_status()["recording"]:
            return None
        return self.core.mark_note()

    def annotate(self, text, mark=None):
        """A reviewer's note into the recording at the servo's current time (or at `mark`,
        from mark_note()), about the part under the hand. False (nothing written) when not
        recording or the note is empty."""
        text = text.strip()
        if self.recording is None or not text or not self.core.recording_status()["recording"]:
            return False
        self.core.annotate(text, mark)
        return True

    # --- the document under the session ---------------------------------------------
    def _document_closed(self):
        """True once the document is closed (its Python object is dead): the servo stops,
        the manipulation under way is dropped with the document, and that is said once."""
        try:
            self.doc.Name
            return False
        except ReferenceError:
            pass
        self.core.stop()
        self._say_recorded()
        self.active = self.original = self.frame = None
        self.rebuilds = {}
        self.closed = True
        _error(self.messages, "the document was closed: haptics stopped")
        return True

    def _deleted(self, ref):
        """The part's object (or the object its placement is written to) is no longer in
        the document: deleted, or its document closed."""
        try:
            return any(self.doc.getObject(o.Name) is None for o in (ref.root, ref.obj) if o is not None)
        except (ReferenceError, RuntimeError):   # FreeCAD: "not part of a document" once removed
            return True

    def _part_deleted(self, ref):
        """A part not held was deleted: the core would go on feeling it where it was, so
        haptics stop (a move still open is committed, as stop() does) and say why."""
        self.stop()
        self.halted = True
        _error(self.messages, "%s was deleted from the document: haptics stopped (Start again to go on "
                              "without it)" % ref.label)

    def _document_changed_under_the_move(self):
        """While a part is moved: if it was deleted, the move so far and the deletion stay
        one undo step (undoing it brings the part back where it was) and haptics stop, as
        the core cannot go on holding it; if the move's transaction was closed under it (the
        user's undo, or another command's commit), the move is over: undone by an undo, so
        the loop restarts with every part where the document has it. True when haptics
        stopped here."""
        if self.active is None:
            return False
        ref = self.parts[self.active]
        if self._deleted(ref):
            self.doc.commitTransaction()
            self.active = self.original = self.frame = None
            self.core.stop()
            self._say_recorded()
            self.halted = True
            _error(self.messages, "%s was deleted while it was held: haptics stopped (Start again to go on "
                                  "without it; one undo brings it back where it was)" % ref.label)
            return True
        if self._move_closed_under_it():
            self.active = self.original = self.frame = None
            placements = []
            for index, part in enumerate(self.parts):
                try:
                    placements.append(placement_numbers(part.global_placement()))
                except Exception:   # deleted meanwhile: where the core had it
                    placements.append(tuple(self.core.snapshot()["placements"][index]))
            self.core.restart(placements)
            self.restarts += 1
            _warn(self.messages, "the move of %s was undone while it was held (an undo or redo closed it): haptics "
                                 "restarted with the parts where the document has them" % ref.label)
        return False

    def stop(self):
        """Stops the servo thread; a manipulation still open is committed where it is.
        Rebuilds in flight are cancelled. A closed document is left alone."""
        if self.closed or self._document_closed():
            for build, _label in self.rebuilds.values():
                drain(build)
            self.rebuilds = {}
            return
        self.core.stop()
        self._say_recorded()
        if self.scene and self.core.scene_mode:
            self._say_models()   # the models built since the last tick get their line too
        for build, _label in self.rebuilds.values():
            drain(build)
        self.rebuilds = {}
        if self.active is not None:
            self._apply(self.core.snapshot())
            self._commit()

    def cancel(self):
        """Esc: stops the servo thread; a manipulation still open is aborted (no undo
        entry, the part back where it was) and the report view says "cancelled"."""
        if self.closed or self._document_closed():
            return
        self.core.stop()
        self._say_recorded()
        if self.active is not None:
            self._abort("cancelled", _warn)
        else:
            _warn(self.messages, "cancelled, haptics stopped (nothing was being moved)")

    @property
    def running(self):
        return self.core.running

    # --- the GUI timer ----------------------------------------------------------------
    def tick(self):
        """Read a snapshot and bring the document up to date. Returns the snapshot.
        What the document did meanwhile is looked at first: closed, the held part deleted,
        the move's transaction undone (_document_changed_under_the_move)."""
        if self.closed or self.halted or self._document_closed() or self._document_changed_under_the_move():
            return self.core.snapshot()
        snap = self.core.snapshot()
        if self._device_hand and snap["tick"] > 0:   # a HID device, the arm: the hand it last read
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
        contact = snap.get("contact")
        if contact is not None and contact["part"] >= 0:
            self.last_contact = contact
        if self.active is not None:
            self._apply(snap)
            if state != "MANIPULATE" or grasped != self.active or "release" in events:
                self._say_interference()
                self._commit()
        if self.active is None and state == "MANIPULATE" and 0 <= grasped < len(self.parts):
            self._begin(grasped)
            self._apply(snap)
        elif self.active is None and {"lift", "release"} <= events:
            # A whole manipulation between two ticks: move what moved, one step each. What
            # moved is read before anything is written: a part of a linked instance moves
            # the other parts of its instance in the document, not in the core.
            moved = [index for index, ref in enumerate(self.parts)
                     if not same_placement(to_placement(snap["placements"][index]), ref.global_placement())]
            for index in moved:
                self._begin(index)
                self._apply(snap)
                self._commit()
        self.state = state
        if self.core.running and self.scene:
            self.feed_shapes()
            self._watch_scene(state, snap)
        elif self.core.running:
            self._watch_edits(state, snap)
        return snap

    WATCH_BUDGET_S = 0.003   # scene mode: the edit watch's share of a GUI tick

    def _rebuild(self, index, ref, shape):
        """Part `index`'s shape was edited: its own model is built off the GUI thread (an
        earlier rebuild in flight is dropped)."""
        self.shapes[index] = shape
        previous = self.rebuilds.pop(index, None)
        if previous is not None:
            drain(previous[0])
        if shape.isNull():
            _warn(self.messages, "%s changed to an empty shape: keeping its previous model" % ref.label)
            return
        self.rebuilds[index] = (core.ModelBuild([part_request(ref, self.default_density, shape)]), ref.label)
        _warn(self.messages, "%s changed: rebuilding its model" % ref.label)

    def _finished_rebuilds(self):
        """The rebuilds that finished, taken out of self.rebuilds: (index, build, label) of
        each that built its part; a failed one is said and its part keeps its model."""
        done = []
        for index in sorted(self.rebuilds):
            build, label = self.rebuilds[index]
            if not build.progress()["finished"]:
                continue
            del self.rebuilds[index]
            errors = build.errors()
            if errors:
                _warn(self.messages, "rebuild of %s failed: %s; keeping its previous model" % (label, errors[0][2]))
                continue
            done.append((index, build, label))
        return done

    def _swap_rebuilt(self):
        """Scene mode: finished rebuilds are felt from the next servo tick, held or not (a
        held part keeps the weight it was lifted with)."""
        for index, build, label in self._finished_rebuilds():
            info = self.core.replace_scene_part(index, build)
            self.rebuilt[index] += 1
            _say_part(self.part_reports, label, info)
            _warn(self.messages, "%s rebuilt: its new shape is felt now" % label)

    def _watch_scene(self, state, snap):
        """Scene mode: the edit watch of _watch_edits, a few parts per tick (round robin
        within WATCH_BUDGET_S), so that a thousand parts cost the GUI no more than ten. A
        part placed elsewhere by the document restarts the loop with every part where the
        core or the document has it (when no part is held); a part whose shape changed
        gets its own model rebuilt off the GUI thread and felt as soon as it is built."""
        import time
        if not self.parts:
            return
        start, moved = time.monotonic(), {}
        for _ in range(len(self.parts)):
            if time.monotonic() - start > self.WATCH_BUDGET_S:
                break
            index = self._sweep
            self._sweep = (self._sweep + 1) % len(self.parts)
            ref = self.parts[index]
            if self._deleted(ref):
                self._part_deleted(ref)
                return
            try:
                shape = ref.global_shape()
            except Exception:   # unreadable meanwhile: it stays where the core has it
                continue
            if self.shapes[index] is None:
                self.shapes[index] = shape
            elif not shape.isPartner(self.shapes[index]):
                self._rebuild(index, ref, shape)
            if self.active is None and state not in HOLDING:
                core_placement = to_placement(snap["placements"][index])
                if not same_placement(shape.Placement, core_placement, 1e-6):
                    moved[index] = shape.Placement
        self._swap_rebuilt()
        if not moved:
            return
        placements = [placement_numbers(moved[i]) if i in moved else tuple(p)
                      for i, p in enumerate(snap["placements"])]
        self.core.restart(placements)
        self.restarts += 1
        _warn(self.messages, "%s moved in the document: haptics restarted with the parts where the document has them"
              % ", ".join(self.parts[i].label for i in sorted(moved)))

    # --- edits while running ----------------------------------------------------------
    def _watch_edits(self, state, snap):
        """A part whose Shape changed (a recompute made a new shape: TShape identity, so
        Placement changes do not count) gets its model rebuilt on a worker thread; finished
        rebuilds are swapped in when no part is held (not in GRASP or MANIPULATE, no move
        open): the servo loop is restarted with the new scene, the parts where the document
        has them, and the report view says so. Untouched parts keep their models.
        A part the document placed elsewhere than the core has it (an undo, a Placement
        typed in, its App::Part moved) restarts the loop the same way, without a rebuild."""
        shapes = []   # per part: its global shape now, None if it cannot be read (deleted meanwhile)
        for index, ref in enumerate(self.parts):
            if self._deleted(ref):
                self._part_deleted(ref)
                return
            try:
                shape = ref.global_shape()
            except Exception:   # the object was deleted meanwhile: leave its model be
                shapes.append(None)
                continue
            shapes.append(shape)
            if not shape.isPartner(self.shapes[index]):
                self._rebuild(index, ref, shape)
        if _DRAINING:
            drain()
        if self.active is not None or state in HOLDING:
            return
        placements = []   # where the document has the parts (global)
        moved = []
        for index, ref in enumerate(self.parts):
            core_placement = to_placement(snap["placements"][index])
            placement = core_placement if shapes[index] is None else shapes[index].Placement
            if not same_placement(placement, core_placement, 1e-6):
                moved.append(ref.label)
            placements.append(placement_numbers(placement))
        swapped = []
        for index, build, label in self._finished_rebuilds():
            self.core.replace_part(index, build)
            self.rebuilt[index] += 1
            swapped.append(label)
            _say_part(self.part_reports, label, self.core.part_info(index))
        if not swapped and not moved:
            return
        self.core.restart(placements)
        self.restarts += 1
        if swapped:
            _warn(self.messages, "%s rebuilt: haptics restarted with the new shape" % ", ".join(swapped))
        if moved:
            _warn(self.messages, "%s moved in the document: haptics restarted with the parts where the "
                  "document has them" % ", ".join(moved))

    def _move_closed_under_it(self):
        """Whether the move's transaction was closed or undone by someone else. FreeCAD makes
        a transaction at its first property change, not at openTransaction(): until the
        move has written a placement it has none (taking that for a closed one restarted
        the loop mid-lift whenever the first GUI tick of a move found the part not yet
        moved), and an undo or redo meanwhile shows in the undo and redo counts. A document
        with undo off has neither, and nothing can undo the move."""
        if not self.doc.UndoMode:
            return False
        if (self.doc.UndoCount, self.doc.RedoCount) != self._undo_counts:
            return True
        return self._move_written and not self.doc.HasPendingTransaction

    # --- internals --------------------------------------------------------------------
    def _begin(self, index):
        ref = self.parts[index]
        self.active = index
        self.original = ref.placement()
        self.frame = ref.frame()
        self.doc.openTransaction("Haptic move %s" % ref.label)
        self._move_written = False
        self._undo_counts = (self.doc.UndoCount, self.doc.RedoCount)

    def _apply(self, snap):
        ref = self.parts[self.active]
        # The core has the global placement; the object keeps its own, relative to the
        # containers and links above it (PartRef.frame()).
        before, after = self.frame
        placement = before.inverse().multiply(to_placement(snap["placements"][self.active])).multiply(after.inverse())
        if not same_placement(placement, ref.placement()):
            ref.set_placement(placement)
            self._move_written = True   # the transaction exists now, counted in UndoCount
            self._undo_counts = (self.doc.UndoCount, self.doc.RedoCount)

    def _say_interference(self):
        """A part put down where it collides (contact off, or a part without its contact
        shell yet): what it is in interference with, and how deep, in the report view. The
        last clearance the GUI saw while it was carried (at most one GUI tick old)."""
        c, self.last_contact = self.last_contact, None
        if c is None or c["part"] != self.active or not c["exact"] or c["clearance_mm"] > -INTERFERENCE_MM:
            return
        other = self.parts[c["other_part"]].label if 0 <= c["other_part"] < len(self.parts) else "?"
        _warn(self.messages, "%s put down in interference with %s, %.3f mm deep (its Face%d, Face%d of %s)"
              % (self.parts[self.active].label, other, -c["clearance_mm"], c["held_face"], c["other_face"], other))

    def _commit(self):
        self.doc.commitTransaction()
        self.active = None
        self.original = None
        self.frame = None
        self.moves += 1

    def _on_fault(self, snap):
        # The core reset the grasp (every part back at its start pose): parts moved earlier
        # in this session would no longer match the document, so the session ends here.
        self.core.stop()
        self._abort("device fault (%s), haptics stopped" % snap["fault"], _error)

    def _abort(self, why, say):
        """Aborts the open manipulation (if any): its transaction, the part back."""
        if self.active is not None:
            ref = self.parts[self.active]
            self.doc.abortTransaction()
            if not same_placement(ref.placement(), self.original):  # undo off: put it back ourselves
                ref.set_placement(self.original)
            self.active = None
            self.original = None
            self.frame = None
            self.aborted += 1
            say(self.messages, "%s: move of %s aborted, the part is back where it was" % (why, ref.label))
        else:
            say(self.messages, "%s: the grasp was reset" % why)


def layout_dirs():
    """Where HID layouts (*.json) are looked for: the package's devices/ folder, then the
    user's <FreeCAD user data>/HapticGrasp/devices/."""
    import os
    # The package's own folder, not the compiled module's: installed from the .deb the module
    # is in Python's dist-packages and the layouts stay with the workbench.
    here = os.path.dirname(os.path.realpath(__file__))
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


def demo_script(part, lift_mm=50.0, move_mm=(0.0, 100.0, 0.0), lift=True, turn_rad=0.0, squeeze_mm=1.0):
    """A scripted hand for `part` (a PartRef or a document object; document coordinates): fingertips come in along x on
    either side of its bounding box centre, grasp, then (lift=True) lift by lift_mm, carry
    by move_mm while turning it by turn_rad about the vertical through its centre, put the
    part down and release, or (lift=False) open again without lifting.
    Once lifted (MANIPULATE) the part follows the midpoint of the fingertips rigidly, so it
    ends displaced by move_mm (plus the fraction of a millimetre the midpoint moved while
    the fingers closed). Each fingertip ends squeeze_mm inside the box (the multi-finger
    method lifts only once friction can carry the weight: m g / (2 mu k) each, 12 mm for the
    2 kg cylinder). Returns (keys, frame Placement)."""
    box = global_bound_box(part)
    half = 0.5 * box.XLength
    open_, inside = half + 20.0, half - 0.5 * squeeze_mm
    squeezed = half - squeeze_mm
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
