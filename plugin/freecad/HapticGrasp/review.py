"""The review of a recorded session (the Review panel's model; no Qt, runs in freecadcmd).

A recording (core.open_review: read once, frames at a viewer's rate, every event, the parts'
pose keys and their last recorded shapes) is matched to the parts of a document by name,
and each matched part is compared with the recorded one BY CONTENT (faces, volume, centre
of gravity in its own frame): a part edited since the session would replay a motion that no
longer fits it, so the reviewer is told, one line per part.

Playing back never writes the document: preview() moves the parts' view providers (their
root SoTransform, as FreeCAD's own Placement dialog previews), so there is no undo entry and
the document is not marked modified; restore() puts every touched view provider back where
its object's Placement says. apply() is the only write: the parts where the recording has
them at the cursor, in one transaction (one undo step).

open_without_document() reviews a recording with no document at all: a new document holding
one Part::Feature per recorded part, built from the BREPs the recording carries.
"""
import json
import math
import os

import FreeCAD as App
import Part

from . import session as hs

core = hs.core
translate = App.Qt.translate   # the warnings and notes the Review panel shows

APPLY_TRANSACTION = "Apply review pose"
NOTE_PREFIX = "note: "
FAULT_PREFIX = "fault: "


def reviews_folder(doc):
    """Where sessions on `doc` are recorded (session.recording_path's folder, not created):
    <document folder>/<document name>.reviews, or the unsaved documents' folder (also for
    doc None)."""
    if doc is not None and doc.FileName:
        name = os.path.splitext(os.path.basename(doc.FileName))[0]
        return os.path.join(os.path.dirname(doc.FileName), name + ".reviews")
    return os.path.expanduser(hs.UNSAVED_REVIEWS_DIR)


def _placement_text(p):
    return "(%.3f, %.3f, %.3f) mm" % (p.Base.x, p.Base.y, p.Base.z)


def _differences(ref_shape, recorded):
    """Why a document part's shape (own frame) is not the recorded one: [] when equal by
    content. Faces must be equal (when the recording knows them), the volume within 1e-6 of
    the recorded one, the centre of gravity within 1e-6 of the recorded box's diagonal. A
    part recorded only as a stand-in box (coarse) is compared by its bounding box."""
    (x0, y0, z0), (x1, y1, z1) = recorded["bounds_mm"]
    diagonal = math.sqrt((x1 - x0) ** 2 + (y1 - y0) ** 2 + (z1 - z0) ** 2)
    if recorded.get("coarse"):
        # Only a box was known: FreeCAD's BoundBox depends on the display's triangulation
        # (up to a fraction of a per cent), so the box is compared loosely.
        box = ref_shape.BoundBox
        now = (box.XMin, box.YMin, box.ZMin, box.XMax, box.YMax, box.ZMax)
        if max(abs(a - b) for a, b in zip(now, (x0, y0, z0, x1, y1, z1))) > 1e-2 * diagonal + 1e-6:
            return ["bounding box (%.3f, %.3f, %.3f)-(%.3f, %.3f, %.3f) mm, recorded (%.3f, %.3f, %.3f)-"
                    "(%.3f, %.3f, %.3f) mm" % (now + (x0, y0, z0, x1, y1, z1))]
        return []
    why = []
    faces = recorded.get("faces", 0)
    if faces > 0 and len(ref_shape.Faces) != faces:
        why.append("%d faces, recorded %d" % (len(ref_shape.Faces), faces))
    volume, recorded_volume = ref_shape.Volume, recorded["volume_mm3"]
    if abs(volume - recorded_volume) > 1e-6 * abs(recorded_volume) + 1e-9:
        why.append("volume %.6g mm^3, recorded %.6g mm^3" % (volume, recorded_volume))
    else:   # a different volume already says it; a centre compared then would only repeat it
        centre, recorded_centre = ref_shape.CenterOfGravity, App.Vector(*recorded["centre_mm"])
        if (centre - recorded_centre).Length > 1e-6 * diagonal + 1e-9:
            why.append("centre of gravity moved by %.6g mm in the part's own frame"
                       % (centre - recorded_centre).Length)
    return why


def _writer(ref):
    """The object (and array element) a PartRef's placement is written to: parts of one
    linked instance share it, and are moved once."""
    return (ref.obj, ref.index)


class Review:
    """A recording opened for review, matched to a document's parts (match()).

    track: the core's ReviewTrack; info: the recording_info dict; parts: the recorded parts
    (dicts: name, placement, faces, volume_mm3, centre_mm, bounds_mm, backend, coarse,
    has_shape); refs: per recorded part its PartRef in the document, or None; warnings:
    one line per recorded part that is missing or changed, and per document part that is
    not in the recording; recording_warnings: what the recording itself says (cut short,
    dropped ticks, a recorder error)."""

    def __init__(self, path, doc=None, frame_rate_hz=60.0):
        self.path = path
        try:
            self.track = core.open_review(path, frame_rate_hz)
        except RuntimeError as e:
            raise RuntimeError("%s cannot be reviewed: %s" % (path, e)) from e
        self.info = json.loads(self.track.info_json)
        self.parts = list(self.track.parts)
        self.duration_s = self.track.duration_s
        self.frame_times = list(self.track.frame_times())
        self.moved = list(self.track.moved_parts)
        self.events = [tuple(e) for e in self.track.events]
        self.annotations = [tuple(a) for a in self.track.annotations]
        self.recording_warnings = list(self.info.get("warnings", []))
        self.doc = None
        self.refs = [None] * len(self.parts)
        self.warnings = []
        self.changed = []      # recorded part indices whose shape differs from the document's
        self.missing = []      # recorded part indices with no part in the document
        self.extra = []        # PartRefs of the document not in the recording
        self.displaced = []    # unmoved parts the document has elsewhere than the recording's start
        self.stand_ins = set()  # recorded parts open_without_document() showed as their boxes
        self._touched = {}     # writer -> (view object, PartRef): what preview() moved
        self._said_unpreviewable = set()
        if doc is not None:
            self.match(doc)

    # --- the document -----------------------------------------------------------------
    def match(self, doc):
        """Maps the recorded parts to the parts a session on `doc` would have
        (session.collect_solids) by name (PartRef.label, as the live session named them);
        when the counts are equal, the parts left unmatched are paired in order (a renamed
        part). Compares each pair by content. Returns the warnings (also in self.warnings)."""
        self.restore()
        messages = []
        refs = hs.collect_solids(doc, messages)
        self.doc = doc
        self.refs = [None] * len(self.parts)
        self.warnings, self.changed, self.missing, self.extra, self.displaced = [], [], [], [], []
        taken = set()
        by_name = {}
        for k, ref in enumerate(refs):
            by_name.setdefault(ref.label, []).append(k)
        for i, part in enumerate(self.parts):
            for k in by_name.get(part["name"], []):
                if k not in taken:
                    self.refs[i] = refs[k]
                    taken.add(k)
                    break
        if len(refs) == len(self.parts):
            for i, part in enumerate(self.parts):
                if self.refs[i] is None and i not in taken:
                    self.refs[i] = refs[i]
                    taken.add(i)
                    self.warnings.append(translate("HapticGrasp", "%s: not in the document by that name, matched to "
                                                                  "%s (the same place in the order)")
                                         % (part["name"], refs[i].label))
        for i, part in enumerate(self.parts):
            ref = self.refs[i]
            if ref is None:
                self.missing.append(i)
                self.warnings.append(translate("HapticGrasp", "%s: not in the document, not shown") % part["name"])
                continue
            if i in self.stand_ins:
                continue   # said when it was made
            try:
                why = _differences(ref.shape(), part)
            except Exception as e:   # a shape that cannot be read counts as changed
                why = ["its shape cannot be read: %s" % e]
            if why:
                self.changed.append(i)
                self.warnings.append(translate("HapticGrasp", "%s: changed since the recording (%s); its recorded "
                                                              "motion is shown on the part as it is now")
                                     % (ref.label, "; ".join(why)))
            if i not in self.moved:
                recorded = hs.to_placement(part["placement"])
                if not hs.same_placement(ref.global_placement(), recorded, 1e-6):
                    self.displaced.append(i)
                    self.warnings.append(translate("HapticGrasp", "%s: placed elsewhere in the document than in the "
                                                                  "recording: shown at the recorded %s")
                                         % (ref.label, _placement_text(recorded)))
        for k, ref in enumerate(refs):
            if k not in taken:
                self.extra.append(ref)
                self.warnings.append(translate("HapticGrasp", "%s: not in the recording, left where it is") % ref.label)
        return self.warnings

    # --- the timeline -------------------------------------------------------------------
    def frame_index(self, t):
        return self.track.frame_at(t)

    def frame(self, t):
        """The recorded frame at time t (the last one at or before it): a dict as
        core.ReviewTrack.frame gives it."""
        return self.track.frame(self.track.frame_at(t))

    def step(self, t, direction):
        """The time of the frame after (direction > 0) or before (< 0) the cursor at t;
        the first or last frame at the ends."""
        i = self.track.frame_at(t)
        if direction > 0:
            i = min(i + 1, len(self.frame_times) - 1)
        elif self.frame_times[i] >= t - 1e-9:   # on a frame: the one before it
            i = max(i - 1, 0)
        return self.frame_times[i]

    def timeline(self):
        """Events and annotations in time order: (time_s, text, kind) with kind "event",
        "fault" or "note"; notes' texts name their part and where the hand was."""
        items = [(t, text, "fault" if fault else "event") for t, text, fault in self.events]
        for t, text, part, (x, y, z) in self.annotations:
            where = translate("HapticGrasp", "hand at (%.0f, %.0f, %.0f) mm") % (x, y, z)
            items.append((t, "%s (%s)" % (text, part + ", " + where if part else where), "note"))
        return sorted(items, key=lambda item: item[0])

    def part_name(self, index):
        return self.parts[index]["name"] if 0 <= index < len(self.parts) else ""

    # --- poses --------------------------------------------------------------------------
    def placements_at(self, t):
        """{recorded part index: global Placement} at time t of every part the review
        places: the parts that moved in the session, and the ones the document has
        elsewhere than the recording's start (they stand at their recorded placement)."""
        out = {i: hs.to_placement(p) for i, p in self.track.placements_at(t).items()}
        for i in self.displaced:
            out.setdefault(i, hs.to_placement(self.parts[i]["placement"]))
        return out

    def poses_at(self, t):
        """{PartRef: global Placement} at time t of the matched parts placements_at() gives."""
        return {self.refs[i]: p for i, p in sorted(self.placements_at(t).items()) if self.refs[i] is not None}

    def grasped_rotation(self, t, frame=None):
        """The grasped part's Rotation at t while held (the overlay's grasp frame), else None."""
        frame = frame or self.frame(t)
        grasped = frame["grasped"]
        if frame["state"] not in hs.HOLDING or not 0 <= grasped < len(self.parts):
            return None
        placement = self.placements_at(t).get(grasped) or hs.to_placement(self.parts[grasped]["placement"])
        return placement.Rotation

    def _own_placements(self, t):
        """[(PartRef, its object's own placement)] at t, one per written object."""
        out, seen = [], set()
        for ref, placement in self.poses_at(t).items():
            if _writer(ref) in seen:
                continue
            seen.add(_writer(ref))
            before, after = ref.frame()
            out.append((ref, before.inverse().multiply(placement).multiply(after.inverse())))
        return out

    def _view_object(self, ref):
        """The view provider showing ref's own placement, or None (no GUI; a link array
        element without element objects: its elements have no view provider of their own)."""
        if ref.index is None:
            return getattr(ref.obj, "ViewObject", None)
        elements = ref.obj.ElementList
        if elements:
            return getattr(elements[ref.index], "ViewObject", None)
        if App.GuiUp and ref.label not in self._said_unpreviewable:
            self._said_unpreviewable.add(ref.label)
            self.warnings.append(translate("HapticGrasp", "%s: an element of a link array whose elements are not "
                                                          "shown as objects (Show Element off): not moved by the "
                                                          "preview; Apply still sets it") % ref.label)
        return None

    def preview(self, t):
        """Shows the parts where the recording has them at t by moving their view
        providers' transforms: the document, its undo stack and its modified flag stay
        as they are. Returns how many view providers were moved (0 without a GUI)."""
        moved = 0
        for ref, own in self._own_placements(t):
            vobj = self._view_object(ref)
            if vobj is None or not hasattr(vobj, "setTransformation"):
                continue
            vobj.setTransformation(own.toMatrix())
            self._touched[_writer(ref)] = (vobj, ref)
            moved += 1
        return moved

    def restore(self):
        """Every view provider preview() moved back where its object's placement has it."""
        touched, self._touched = self._touched, {}
        for vobj, ref in touched.values():
            try:
                vobj.setTransformation(ref.placement().toMatrix())
            except Exception:   # the object was deleted meanwhile: nothing to restore
                pass

    def apply(self, t):
        """Sets the parts where the recording has them at t: one transaction, so one undo
        step ("Apply review pose"). Returns the labels of the parts written (none: no undo
        entry)."""
        if self.doc is None:
            raise RuntimeError("no document to apply the pose to")
        writes = [(ref, own) for ref, own in self._own_placements(t) if not hs.same_placement(ref.placement(), own)]
        if not writes:
            return []
        self.doc.openTransaction(APPLY_TRANSACTION)
        try:
            for ref, own in writes:
                ref.set_placement(own)
        except Exception:
            self.doc.abortTransaction()
            raise
        self.doc.commitTransaction()
        self.doc.recompute()
        return [ref.label for ref, _own in writes]


def _part_shape(track, index, part):
    """The recorded shape of part `index` (own frame, mm), or None when the recording has
    none. The core gives it as OCCT text BREP (FreeCAD 0.20's importBinary cannot read the
    binary BREP OCCT 7.6 writes). A part recorded in metres is scaled to mm."""
    data = track.part_brep(index)
    if not data:
        return None
    shape = Part.Shape()
    shape.importBrepFromString(data.decode("utf-8"))
    if part.get("unit") == "m":
        shape.scale(1000.0)
    shape.Placement = App.Placement()
    return shape


def _document_name(path):
    stem = os.path.splitext(os.path.basename(path))[0]
    return "Review_" + "".join(c if c.isalnum() else "_" for c in stem)


def open_without_document(path, frame_rate_hz=60.0):
    """Reviews a recording with no document: a new document "Review_<file stem>" with one
    Part::Feature per recorded part, its recorded shape (the BREP attached to the recording)
    at its initial placement, labelled with its recorded name; a part recorded without a
    shape is its bounding box, with a warning. Returns the Review, matched to it."""
    review = Review(path, frame_rate_hz=frame_rate_hz)
    stem = os.path.splitext(os.path.basename(path))[0]
    doc = App.newDocument(_document_name(path), "Review " + stem)
    made = []
    for i, part in enumerate(review.parts):
        shape = None
        try:
            shape = _part_shape(review.track, i, part)
        except Exception as e:
            review.recording_warnings.append(translate("HapticGrasp", "%s: its recorded shape cannot be read (%s)")
                                             % (part["name"], e))
        if shape is None or shape.isNull():
            (x0, y0, z0), (x1, y1, z1) = part["bounds_mm"]
            shape = Part.makeBox(max(x1 - x0, 1e-3), max(y1 - y0, 1e-3), max(z1 - z0, 1e-3), App.Vector(x0, y0, z0))
            review.stand_ins.add(i)
            review.recording_warnings.append("%s: no shape in the recording, shown as its bounding box"
                                             % part["name"])
        feature = doc.addObject("Part::Feature", "Part")
        feature.Shape = shape
        feature.Placement = hs.to_placement(part["placement"])
        feature.Label = part["name"]
        made.append(feature)
    doc.recompute()
    # Labels are unique in a document: a repeated name becomes "<name>001", which the
    # match pairs in order (the counts are equal).
    review.match(doc)
    if doc.UndoMode:
        doc.clearUndos()
    return review
