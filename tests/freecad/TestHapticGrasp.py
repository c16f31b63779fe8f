"""HapticGrasp in real FreeCAD (freecadcmd), no mocks: parts from resources/parts as
document objects, the real servo thread driven by a scripted hand, and the document
updated by HapticSession.tick() as the GUI timer would.

Run: `freecadcmd -t TestHapticGrasp` with the built package in the Mod folder
(tests/freecad/run_freecadcmd.sh does that in a throw-away HOME)."""
import math
import os
import sys
import time
import unittest

import FreeCAD as App
import Part

# FreeCAD puts the package folder (Mod/HapticGrasp) on sys.path; import it as a package.
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.realpath(__file__))))
from HapticGrasp import _hapticgrasp as core  # noqa: E402
from HapticGrasp import session as hs  # noqa: E402

RESOURCES = os.environ.get("HG_RESOURCES_DIR", "")
TICK_S = 1.0 / 50  # the GUI timer's period


def read_part(name):
    shape = Part.Shape()
    shape.importBrep(os.path.join(RESOURCES, "parts", name + ".brep"))
    return shape


def run(session, until_s, on_tick=None):
    """Call tick() at the GUI timer's rate for until_s seconds of servo time; returns the
    states seen, in order, without repeats."""
    states = []
    deadline = time.monotonic() + until_s + 5.0
    while time.monotonic() < deadline:
        snap = session.tick()
        if not states or states[-1] != snap["state"]:
            states.append(snap["state"])
        if on_tick:
            on_tick(snap)
        if snap["time_s"] >= until_s or not session.running:
            break
        time.sleep(TICK_S)
    return states


class HapticGraspDocument(unittest.TestCase):
    def setUp(self):
        self.assertTrue(os.path.isdir(RESOURCES), "HG_RESOURCES_DIR not set: " + RESOURCES)
        self.doc = App.newDocument("HapticGraspTest")
        self.doc.UndoMode = 1  # freecadcmd has undo off
        self.cylinder = self.doc.addObject("Part::Feature", "Cylinder")
        self.cylinder.Shape = read_part("cylinder")
        # The paper's pose: axis along y, at (400, 0, 300) mm; 2 kg.
        self.cylinder.Placement = App.Placement(App.Vector(400, 0, 300), App.Rotation(App.Vector(1, 0, 0), -90))
        self.cylinder.addProperty("App::PropertyFloat", "HapticDensity", "Haptic")
        self.cylinder.HapticDensity = 2.0 / self.cylinder.Shape.Volume * 1e9  # kg/m^3 for 2 kg
        self.block = self.doc.addObject("Part::Feature", "Block")
        self.block.Shape = read_part("block")
        self.block.Placement = App.Placement(App.Vector(-500, 0, 0), App.Rotation())
        self.doc.recompute()
        self.doc.clearUndos()
        self.session = None

    def tearDown(self):
        if self.session is not None:
            self.session.core.stop()
        App.closeDocument(self.doc.Name)

    def make_session(self, lift=True, **script):
        self.session = hs.HapticSession(self.doc)
        self.assertEqual([r.obj.Name for r in self.session.parts], ["Cylinder", "Block"])
        mass = self.session.core.part_info(0)["mass_kg"]
        self.assertAlmostEqual(mass, 2.0, places=6)
        keys, frame = hs.demo_script(self.cylinder, lift=lift, **script)
        self.session.use_hand_script(keys, frame)
        return self.session

    def test_grasp_lift_move_release_moves_the_placement_and_one_undo_restores_it(self):
        before = App.Placement(self.cylinder.Placement)
        block_before = App.Placement(self.block.Placement)
        s = self.make_session()
        s.start()
        states = run(s, s.core.script_duration() + 0.2)
        s.stop()
        self.assertEqual(states[-1], "FREE", states)
        self.assertIn("MANIPULATE", states)
        self.assertEqual(s.moves, 1)
        moved = self.cylinder.Placement.Base - before.Base
        print("moved by (%.3f, %.3f, %.3f) mm, states %s" % (moved.x, moved.y, moved.z, states))
        # The script carries the hand by (0, 100, 0) mm and puts the part down at its height.
        self.assertAlmostEqual(moved.x, 0.0, delta=0.5)
        self.assertAlmostEqual(moved.y, 100.0, delta=0.5)
        self.assertAlmostEqual(moved.z, 0.0, delta=0.5)
        self.assertTrue(self.cylinder.Placement.Rotation.isSame(before.Rotation, 1e-3))
        self.assertTrue(hs.same_placement(self.block.Placement, block_before, 1e-12))
        self.assertEqual(self.doc.UndoNames, ["Haptic move Cylinder"])
        self.doc.undo()
        self.assertTrue(hs.same_placement(self.cylinder.Placement, before), self.cylinder.Placement)
        self.assertEqual(self.doc.UndoCount, 0)

    def test_turning_the_hand_turns_the_part(self):
        before = App.Placement(self.cylinder.Placement)
        s = self.make_session(move_mm=(0.0, 0.0, 0.0), turn_rad=0.5)
        s.start()
        run(s, s.core.script_duration() + 0.2)
        s.stop()
        self.assertEqual(s.moves, 1)
        expected = App.Rotation(App.Vector(0, 0, 1), 0.5 * 180 / 3.141592653589793).multiply(before.Rotation)
        after = self.cylinder.Placement
        print("turned: %s -> %s" % (before.Rotation.Q, after.Rotation.Q))
        self.assertFalse(before.Rotation.isSame(expected, 1e-3))  # the check below can fail
        self.assertTrue(after.Rotation.isSame(expected, 1e-3), (after.Rotation.Q, expected.Q))
        self.assertLess((after.Base - before.Base).Length, 0.5)

    def test_a_manipulation_between_two_ticks_is_still_one_undo_step(self):
        # A GUI busy for the whole manipulation: one tick sees lift and release together.
        before = App.Placement(self.cylinder.Placement)
        s = self.make_session()
        s.start()
        time.sleep(s.core.script_duration() + 0.3)
        snap = s.tick()
        s.stop()
        self.assertEqual(snap["state"], "FREE")
        self.assertIn("lift", snap["event_names"])
        self.assertIn("release", snap["event_names"])
        moved = self.cylinder.Placement.Base - before.Base
        self.assertAlmostEqual(moved.y, 100.0, delta=0.5)
        self.assertEqual(self.doc.UndoNames, ["Haptic move Cylinder"])
        self.doc.undo()
        self.assertTrue(hs.same_placement(self.cylinder.Placement, before))

    def test_release_from_grasp_leaves_the_document_unchanged(self):
        before = App.Placement(self.cylinder.Placement)
        s = self.make_session(lift=False)
        s.start()
        states = run(s, s.core.script_duration() + 0.2)
        s.stop()
        self.assertIn("GRASP", states)
        self.assertNotIn("MANIPULATE", states)
        self.assertEqual(states[-1], "FREE", states)
        self.assertTrue(hs.same_placement(self.cylinder.Placement, before, 0.0))
        self.assertEqual(self.doc.UndoCount, 0)
        self.assertEqual(s.moves, 0)

    def test_a_non_solid_is_skipped_with_one_warning(self):
        face = self.doc.addObject("Part::Feature", "Sheet")
        face.Shape = Part.makePlane(100, 100)
        hidden = self.doc.addObject("Part::Feature", "Hidden")
        hidden.Shape = Part.makeBox(10, 10, 10)
        hidden.Visibility = False
        self.session = hs.HapticSession(self.doc)
        self.assertEqual([r.obj.Name for r in self.session.parts], ["Cylinder", "Block"])
        self.assertEqual(len(self.session.messages), 1, self.session.messages)
        self.assertIn("Sheet", self.session.messages[0])
        self.assertIn("not a solid", self.session.messages[0])
        info = self.session.core.part_info(1)
        self.assertEqual(info["faces"], 58)
        self.assertAlmostEqual(info["volume_mm3"], self.block.Shape.Volume, delta=1e-6 * self.block.Shape.Volume)

    def test_a_device_fault_mid_manipulation_aborts_and_restores_the_placement(self):
        before = App.Placement(self.cylinder.Placement)
        s = self.make_session()
        seen = {"moved": False}

        def silence_when_carrying(snap):
            # Silence the device once the part has visibly moved in the document.
            if s.active is not None and (self.cylinder.Placement.Base - before.Base).Length > 5.0:
                seen["moved"] = True
                s.core.set_device_silent(True)

        s.start()
        states = run(s, s.core.script_duration(), on_tick=silence_when_carrying)
        self.assertTrue(seen["moved"], states)
        self.assertFalse(s.running)
        self.assertEqual(s.aborted, 1)
        self.assertEqual(s.moves, 0)
        self.assertIsNone(s.active)
        self.assertTrue(hs.same_placement(self.cylinder.Placement, before), self.cylinder.Placement)
        self.assertEqual(self.doc.UndoCount, 0)
        self.assertEqual(len(s.messages), 1, s.messages)
        self.assertIn("device fault (silent)", s.messages[0])
        self.assertIn("Cylinder", s.messages[0])

    def hand_at(self, keys, frame, t):
        """The demo hand at time t (linear between keys; no turn), document mm."""
        def lerp(a, b, u):
            return tuple(x + (y - x) * u for x, y in zip(a, b))
        t = min(max(t, keys[0][0]), keys[-1][0])
        for k0, k1 in zip(keys, keys[1:]):
            if k0[0] <= t <= k1[0]:
                u = (t - k0[0]) / (k1[0] - k0[0]) if k1[0] > k0[0] else 1.0
                break
        base = (frame.Base.x, frame.Base.y, frame.Base.z)
        shift = lerp(k0[4], k1[4], u)
        return [tuple(b + p + s for b, p, s in zip(base, lerp(k0[i], k1[i], u), shift)) for i in (1, 2, 3)]

    def feed_hand(self, s, keys, frame, until_s, stop_feeding_when=None):
        """Feed the hand at ~200 Hz and tick the document at ~50 Hz for until_s seconds."""
        start = time.monotonic()
        states, n = [], 0
        while time.monotonic() - start < until_s + 5.0 and s.running:
            t = time.monotonic() - start
            if t > until_s:
                break
            if not (stop_feeding_when and stop_feeding_when()):
                s.set_hand(*self.hand_at(keys, frame, t))
            if n % 4 == 0:
                state = s.tick()["state"]
                if not states or states[-1] != state:
                    states.append(state)
            n += 1
            time.sleep(0.005)
        s.tick()
        return states

    def test_a_hand_fed_from_python_moves_the_part(self):
        before = App.Placement(self.cylinder.Placement)
        self.session = s = hs.HapticSession(self.doc)
        s.use_hand_input(hold_s=0.5)
        self.assertEqual(s.core.device_name, "hand input")
        keys, frame = hs.demo_script(self.cylinder, move_mm=(80.0, 0.0, 0.0))
        s.start()
        states = self.feed_hand(s, keys, frame, keys[-1][0] + 0.2)
        s.stop()
        self.assertIn("MANIPULATE", states)
        self.assertEqual(states[-1], "FREE", states)
        moved = self.cylinder.Placement.Base - before.Base
        print("hand input: moved by (%.3f, %.3f, %.3f) mm" % (moved.x, moved.y, moved.z))
        self.assertAlmostEqual(moved.x, 80.0, delta=0.5)
        self.assertAlmostEqual(moved.y, 0.0, delta=0.5)
        self.assertAlmostEqual(moved.z, 0.0, delta=0.5)
        self.assertEqual(self.doc.UndoNames, ["Haptic move Cylinder"])

    def test_the_multi_finger_method_carries_the_part_with_its_sag(self):
        # The resultant-force method: the part rests until the pinch can carry its weight,
        # then hangs m g / k_d below the fingers' shell; put down and released there.
        before = App.Placement(self.cylinder.Placement)
        block_before = App.Placement(self.block.Placement)
        self.session = s = hs.HapticSession(self.doc)
        keys, frame = hs.demo_script(self.cylinder, squeeze_mm=18.0)
        s.use_hand_script(keys, frame)
        s.start(method="multi-finger")
        self.assertEqual(s.core.method, "multi-finger")
        fingertips = []
        states = run(s, s.core.script_duration() + 0.3, lambda snap: fingertips.append(len(snap["fingertips"])))
        s.stop()
        self.assertEqual(set(fingertips) - {0}, {2})   # 0 before the first tick
        self.assertIn("MANIPULATE", states)
        self.assertEqual(states[-1], "FREE", states)
        moved = self.cylinder.Placement.Base - before.Base
        sag = 2.0 * 9.80665 / 800.0 * 1000.0   # m g / k_d, mm
        print("multi-finger: moved by (%.3f, %.3f, %.3f) mm, sag %.1f mm, states %s"
              % (moved.x, moved.y, moved.z, sag, states))
        self.assertAlmostEqual(moved.x, 0.0, delta=1.0)
        self.assertAlmostEqual(moved.y, 100.0, delta=1.0)
        self.assertAlmostEqual(moved.z, -sag, delta=3.0)
        self.assertTrue(hs.same_placement(self.block.Placement, block_before, 1e-12))
        self.assertEqual(self.doc.UndoNames, ["Haptic move Cylinder"])
        self.doc.undo()
        self.assertTrue(hs.same_placement(self.cylinder.Placement, before), self.cylinder.Placement)

    def test_an_unknown_method_is_refused(self):
        self.session = s = self.make_session()
        with self.assertRaises(ValueError):
            s.start(method="three-finger")
        self.assertFalse(s.running)

    def test_a_hand_that_goes_silent_mid_manipulation_aborts(self):
        before = App.Placement(self.cylinder.Placement)
        self.session = s = hs.HapticSession(self.doc)
        s.use_hand_input(hold_s=0.2)
        keys, frame = hs.demo_script(self.cylinder)

        def carrying():
            return s.active is not None and (self.cylinder.Placement.Base - before.Base).Length > 5.0

        s.start()
        self.feed_hand(s, keys, frame, keys[-1][0], stop_feeding_when=carrying)
        self.assertFalse(s.running)
        self.assertEqual(s.aborted, 1)
        self.assertTrue(hs.same_placement(self.cylinder.Placement, before), self.cylinder.Placement)
        self.assertEqual(self.doc.UndoCount, 0)
        self.assertEqual(len(s.messages), 1, s.messages)
        self.assertIn("device fault (silent)", s.messages[0])

    def test_a_changed_shape_is_rebuilt_by_the_next_session(self):
        # Models are built when a session is made (at Start): edit the radius in between.
        tube = self.doc.addObject("Part::Cylinder", "Tube")
        tube.Radius, tube.Height = 20.0, 50.0
        tube.Placement = App.Placement(App.Vector(0, 500, 0), App.Rotation())
        self.doc.recompute()
        first = hs.HapticSession(self.doc)
        self.session = first
        index = [r.obj.Name for r in first.parts].index("Tube")
        keys, frame = hs.demo_script(tube, lift=False)
        first.use_hand_script(keys, frame)
        first.start()
        run(first, 0.2)
        first.stop()
        small = first.core.part_info(index)["volume_mm3"]
        self.assertAlmostEqual(small, tube.Shape.Volume, delta=1e-3 * tube.Shape.Volume)
        tube.Radius = 30.0
        self.doc.recompute()
        self.session = second = hs.HapticSession(self.doc)
        big = second.core.part_info([r.obj.Name for r in second.parts].index("Tube"))["volume_mm3"]
        print("tube volume %.0f -> %.0f mm^3" % (small, big))
        self.assertAlmostEqual(big, tube.Shape.Volume, delta=1e-3 * tube.Shape.Volume)
        self.assertAlmostEqual(big / small, 2.25, delta=0.01)

    def test_a_broken_part_is_refused_with_a_clear_error(self):
        with self.assertRaises(ValueError):
            core.part_info("DBRep_DrawableShape\nCASCADE Topology V1, (c) Matra-Datavision\nLocations 3\n")


class PartsIntoTheSession(unittest.TestCase):
    """How parts get into a session: models built on the core's worker thread with
    progress and cancel, a bad part skipped by name, an edited part rebuilt mid-session,
    parts inside App::Part containers, and parts marked graspable."""

    setUp = HapticGraspDocument.setUp
    tearDown = HapticGraspDocument.tearDown

    def add_blocks(self, n):
        for i in range(n):
            extra = self.doc.addObject("Part::Feature", "Extra%d" % i)
            extra.Shape = read_part("block")
            extra.Placement = App.Placement(App.Vector(-500, 400 * (i + 1), 0), App.Rotation())

    def test_models_are_built_off_the_calling_thread_with_progress(self):
        self.add_blocks(4)
        t0 = time.monotonic()
        budget = hs.HapticSession.EXPORT_BUDGET_S
        hs.HapticSession.EXPORT_BUDGET_S = 0.0   # one BREP export per poll
        try:
            s = self.session = hs.HapticSession(self.doc, wait=False)
            returned_after = time.monotonic() - t0
            first = s.build_progress()
            self.assertEqual(len(s._requested), 1)   # the others are exported by later polls
            s.poll_build()
            self.assertEqual(len(s._requested), 2)
        finally:
            hs.HapticSession.EXPORT_BUDGET_S = budget
        polls, seen, names = 0, [], set()
        deadline = time.monotonic() + 120
        while not s.poll_build() and time.monotonic() < deadline:
            done, total, current = s.build_progress()
            polls += 1
            if not seen or seen[-1] != done:
                seen.append(done)
            if current:
                names.add(current)
            self.assertFalse(s.ready)
            time.sleep(0.005)   # the calling (GUI) thread keeps running meanwhile
        build_s = time.monotonic() - t0
        print("build of 6 parts: constructor returned after %.3f s (progress %s), built in %.2f s, %d polls, "
              "done %s, names %s" % (returned_after, first, build_s, polls, seen, sorted(names)))
        self.assertTrue(s.ready)
        self.assertEqual(first[1], 6)
        self.assertLessEqual(first[0], 1)                # the constructor did not wait
        self.assertLessEqual(seen[0], 2)
        self.assertGreaterEqual(len(seen), 3, seen)     # progress moved across polls
        self.assertEqual(seen, sorted(seen))
        self.assertEqual(s.build_progress(), (6, 6, ""))
        self.assertGreater(polls, 10)
        self.assertIn("Extra0", names)
        self.assertEqual(s.core.part_count(), 6)
        self.assertEqual([r.obj.Name for r in s.parts], ["Cylinder", "Block", "Extra0", "Extra1", "Extra2", "Extra3"])
        self.assertEqual(s.messages, [])

    def test_cancel_leaves_no_half_built_session(self):
        self.add_blocks(4)
        s = self.session = hs.HapticSession(self.doc, wait=False)
        deadline = time.monotonic() + 60
        while s.build_progress()[0] < 1 and time.monotonic() < deadline:
            time.sleep(0.002)
        done = s.build_progress()[0]
        s.cancel_build()
        self.assertGreaterEqual(done, 1)
        self.assertTrue(s.cancelled)
        self.assertFalse(s.ready)
        self.assertTrue(s.poll_build())
        self.assertEqual(s.parts, [])
        self.assertEqual(s.core.part_count(), 0)
        with self.assertRaises(RuntimeError):
            s.start()
        self.assertEqual(len(s.messages), 1, s.messages)
        self.assertIn("cancelled", s.messages[0])
        # The worker finishes the part in progress and stops: nothing more is built.
        while hs.drain() and time.monotonic() < deadline:
            time.sleep(0.01)
        self.assertEqual(hs.drain(), 0)
        self.assertEqual(s.core.part_count(), 0)

    def test_a_bad_part_is_skipped_with_its_name_and_the_others_are_kept(self):
        box = Part.makeBox(40, 40, 40)
        broken = self.doc.addObject("Part::Feature", "Broken")
        broken.Label = "Open box"
        broken.Shape = Part.Solid(Part.Shell(box.Faces[:-1]))   # a "solid" with a face missing
        broken.Placement = App.Placement(App.Vector(0, -400, 0), App.Rotation())
        self.assertEqual(broken.Shape.ShapeType, "Solid")
        s = self.session = hs.HapticSession(self.doc, wait=False)
        self.assertTrue(s.build.wait(120))
        self.assertTrue(s.poll_build())
        self.assertEqual([r.obj.Name for r in s.parts], ["Cylinder", "Block"])
        self.assertEqual(s.core.part_count(), 2)
        self.assertEqual(len(s.messages), 1, s.messages)
        print("bad part: %s" % s.messages[0])
        self.assertTrue(s.messages[0].startswith("skipping Open box: "), s.messages[0])

    def test_an_edited_part_is_rebuilt_mid_session_and_felt_at_its_new_surface(self):
        tube = self.doc.addObject("Part::Cylinder", "Tube")
        tube.Radius, tube.Height = 20.0, 50.0
        tube.Placement = App.Placement(App.Vector(0, 500, 0), App.Rotation())
        self.doc.recompute()
        s = self.session = hs.HapticSession(self.doc)
        names = [r.obj.Name for r in s.parts]
        self.assertEqual(names, ["Cylinder", "Block", "Tube"])
        index = names.index("Tube")
        self.assertAlmostEqual(s.core.part_info(index)["bounds_mm"][1][0], 20.0, delta=1e-6)
        # The index fingertip 25 mm from the axis: outside the 20 mm tube, inside a 30 mm one.
        hand = ((25.0, 500.0, 25.0), (-80.0, 500.0, 25.0), (-30.0, 500.0, 150.0))
        s.use_hand_input(hold_s=0.5)
        s.start()

        def feed(seconds, until=None):
            end = time.monotonic() + seconds
            snap = None
            while time.monotonic() < end:
                s.set_hand(*hand)
                snap = s.tick()
                if until is not None and until():
                    break
                time.sleep(0.01)
            return snap

        snap = feed(0.4)
        self.assertEqual(snap["state"], "FREE")
        self.assertAlmostEqual(snap["forces"][0][0], 0.0, delta=1e-9)
        tube.Radius = 30.0
        self.doc.recompute()
        feed(60.0, until=lambda: s.rebuilt[index] > 0)
        self.assertEqual(s.rebuilt[index], 1, s.messages)
        self.assertTrue(s.running)
        snap = feed(0.4)
        print("after the edit: %s, index force %s N; %s" % (snap["state"], snap["forces"][0], s.messages))
        self.assertEqual(snap["state"], "INDEX CONTACT")
        self.assertGreater(snap["forces"][0][0], 0.1)   # pushed out of the tube, along +x
        self.assertAlmostEqual(s.core.part_info(index)["bounds_mm"][1][0], 30.0, delta=1e-6)
        self.assertAlmostEqual(s.core.part_info(index)["volume_mm3"], tube.Shape.Volume, delta=1e-3 * tube.Shape.Volume)
        # Untouched parts were not rebuilt; one restart swapped the model in, and said so.
        self.assertEqual(s.rebuilt, [0, 0, 1])
        self.assertEqual(s.restarts, 1)
        self.assertEqual(s.messages, ["Tube changed: rebuilding its model",
                                      "Tube rebuilt: haptics restarted with the new shape"])
        s.stop()

    def test_an_edited_partdesign_feature_rebuilds_its_body_only(self):
        body = self.doc.addObject("PartDesign::Body", "Body")
        box = self.doc.addObject("PartDesign::AdditiveBox", "Pad")
        body.addObject(box)
        box.Length, box.Width, box.Height = 40.0, 30.0, 20.0
        body.Placement = App.Placement(App.Vector(0, 700, 0), App.Rotation(App.Vector(0, 0, 1), 30))
        self.doc.recompute()
        s = self.session = hs.HapticSession(self.doc)
        self.assertEqual([r.obj.Name for r in s.parts], ["Cylinder", "Block", "Body"])
        self.assertAlmostEqual(s.core.part_info(2)["bounds_mm"][1][0], 40.0, delta=1e-6)
        s.use_hand_input(hold_s=0.5)
        far = ((0.0, -900.0, 0.0), (0.0, -950.0, 0.0), (0.0, -925.0, 100.0))
        s.start()
        box.Length = 70.0   # the feature is edited, the Body recomputed
        self.doc.recompute()
        deadline = time.monotonic() + 60
        while s.rebuilt[2] == 0 and time.monotonic() < deadline:
            s.set_hand(*far)
            s.tick()
            time.sleep(0.01)
        s.stop()
        self.assertEqual(s.rebuilt, [0, 0, 1])
        self.assertEqual(s.restarts, 1)
        self.assertAlmostEqual(s.core.part_info(2)["bounds_mm"][1][0], 70.0, delta=1e-6)
        self.assertEqual(s.messages, ["Body changed: rebuilding its model",
                                      "Body rebuilt: haptics restarted with the new shape"])

    def test_an_undo_while_running_puts_the_part_back_in_the_core_too(self):
        before = App.Placement(self.cylinder.Placement)
        s = self.session = HapticGraspDocument.make_session(self)
        s.start()
        run(s, s.core.script_duration() + 0.2)
        self.assertTrue(s.running)   # the script is over, the servo loop runs on
        self.assertEqual((s.moves, s.restarts), (1, 0))
        moved = App.Placement(self.cylinder.Placement)
        self.assertAlmostEqual((moved.Base - before.Base).y, 100.0, delta=0.5)
        self.doc.undo()
        self.assertTrue(hs.same_placement(self.cylinder.Placement, before))
        s.tick()   # sees the document's placement differ from the core's: restart
        self.assertEqual(s.restarts, 1)
        snap = s.tick()
        s.stop()
        self.assertTrue(hs.same_placement(hs.to_placement(snap["placements"][0]), before, 1e-6))
        self.assertTrue(hs.same_placement(self.cylinder.Placement, before))
        self.assertEqual(s.rebuilt, [0, 0])
        self.assertEqual(s.messages, ["Cylinder moved in the document: haptics restarted with the parts where "
                                      "the document has them"])

    def test_a_part_inside_nested_app_parts_moves_in_global_coordinates_and_one_undo_restores_it(self):
        # Nested: Outer (translated, turned about z) holds Assembly (translated, turned about
        # a slanted axis), which holds the cylinder.
        outer = self.doc.addObject("App::Part", "Outer")
        outer.Placement = App.Placement(App.Vector(-30, 60, 10), App.Rotation(App.Vector(0, 0, 1), 25))
        assembly = self.doc.addObject("App::Part", "Assembly")
        assembly.Placement = App.Placement(App.Vector(150, -80, 40), App.Rotation(App.Vector(1, 1, 1), 40))
        outer.addObject(assembly)
        self.doc.removeObject("Block")
        assembly.addObject(self.cylinder)
        container = outer.Placement.multiply(assembly.Placement)
        wanted = App.Placement(App.Vector(400, 0, 300), App.Rotation(App.Vector(1, 0, 0), -90))
        self.cylinder.Placement = container.inverse().multiply(wanted)
        self.doc.recompute()
        self.doc.clearUndos()
        self.assertTrue(hs.same_placement(self.cylinder.getGlobalPlacement(), wanted, 1e-9))
        local_before = App.Placement(self.cylinder.Placement)
        self.session = s = hs.HapticSession(self.doc)
        self.assertEqual([r.obj.Name for r in s.parts], ["Cylinder"])   # the App::Parts are no parts
        self.assertAlmostEqual(s.core.part_info(0)["mass_kg"], 2.0, places=6)
        # The core has the global placement.
        self.assertTrue(hs.same_placement(hs.to_placement(s.core.snapshot()["placements"][0]), wanted, 1e-6))
        keys, frame = hs.demo_script(self.cylinder)   # carries the hand (0, 100, 0) mm, global
        s.use_hand_script(keys, frame)
        s.start()
        states = run(s, s.core.script_duration() + 0.2)
        s.stop()
        self.assertIn("MANIPULATE", states)
        self.assertEqual(s.moves, 1)
        self.assertEqual(s.restarts, 0)   # the core and the document agreed all along
        after = self.cylinder.getGlobalPlacement()
        moved = after.Base - wanted.Base
        print("in App::Part: moved by (%.3f, %.3f, %.3f) mm globally; local %s -> %s"
              % (moved.x, moved.y, moved.z, local_before, self.cylinder.Placement))
        self.assertAlmostEqual(moved.x, 0.0, delta=0.5)
        self.assertAlmostEqual(moved.y, 100.0, delta=0.5)
        self.assertAlmostEqual(moved.z, 0.0, delta=0.5)
        self.assertTrue(after.Rotation.isSame(wanted.Rotation, 1e-3))
        # Written back relative to the container, which did not move.
        self.assertTrue(hs.same_placement(container.multiply(self.cylinder.Placement), after, 1e-9))
        self.assertTrue(hs.same_placement(outer.Placement.multiply(assembly.Placement), container, 1e-12))
        self.assertGreater((self.cylinder.Placement.Base - local_before.Base).Length, 50.0)
        self.assertEqual(self.doc.UndoNames, ["Haptic move Cylinder"])
        self.doc.undo()
        self.assertTrue(hs.same_placement(self.cylinder.Placement, local_before, 1e-9), self.cylinder.Placement)
        self.assertTrue(hs.same_placement(self.cylinder.getGlobalPlacement(), wanted, 1e-6))

    def test_only_marked_parts_are_handed_in_once_any_is_marked(self):
        def handed():
            messages = []
            return [r.obj.Name for r in hs.collect_solids(self.doc, messages)], messages

        self.assertEqual(handed(), (["Cylinder", "Block"], []))
        hs.set_graspable([self.block])
        self.assertTrue(hs.is_graspable(self.block))
        self.assertFalse(hs.is_graspable(self.cylinder))
        self.assertEqual(handed(), (["Block"], []))
        self.session = s = hs.HapticSession(self.doc)
        self.assertEqual([r.obj.Name for r in s.parts], ["Block"])
        self.assertEqual(s.core.part_count(), 1)
        # A marked part that is hidden, or not a solid, is named in the report view.
        sheet = self.doc.addObject("Part::Feature", "Sheet")
        sheet.Shape = Part.makePlane(100, 100)
        hidden = self.doc.addObject("Part::Feature", "Hidden")
        hidden.Shape = Part.makeBox(10, 10, 10)
        hidden.Visibility = False
        hs.set_graspable([sheet, hidden])
        names, messages = handed()
        self.assertEqual(names, ["Block"])
        self.assertEqual(len(messages), 2, messages)
        self.assertIn("Sheet: not a solid", messages[0])
        self.assertIn("Hidden: marked graspable but hidden", messages[1])
        # Unmarked again: every visible solid.
        hs.set_graspable([self.block, sheet, hidden], False)
        names, messages = handed()
        self.assertEqual(names, ["Cylinder", "Block"])
        self.assertEqual(len(messages), 1, messages)   # the sheet, visible, not a solid

    def test_containers_and_bodies_hand_in_each_solid_once(self):
        body = self.doc.addObject("PartDesign::Body", "Body")
        box = self.doc.addObject("PartDesign::AdditiveBox", "Box")
        body.addObject(box)
        body.Placement = App.Placement(App.Vector(0, 700, 0), App.Rotation())
        shown = self.doc.addObject("App::Part", "Shown")
        shown.addObject(body)
        hidden = self.doc.addObject("App::Part", "HiddenAssembly")
        inner = self.doc.addObject("Part::Box", "Inner")
        hidden.addObject(inner)
        hidden.Visibility = False
        self.doc.recompute()
        messages = []
        names = [r.obj.Name for r in hs.collect_solids(self.doc, messages)]
        self.assertEqual(names, ["Cylinder", "Block", "Body"])   # not the Box feature, not the App::Parts
        self.assertEqual(messages, [])


class PartReports(unittest.TestCase):
    """Every part handed in is said once in the report view: which penetration back end
    answers it and why. A part with a defect loads on a robust back end and says so; a
    compound of solids is one part, and overlapping solids are measured."""

    setUp = HapticGraspDocument.setUp
    tearDown = HapticGraspDocument.tearDown

    def add(self, name, shape, x):
        obj = self.doc.addObject("Part::Feature", name)
        obj.Shape = shape
        obj.Placement = App.Placement(App.Vector(x, -400, 0), App.Rotation())
        return obj

    def open_session(self):
        self.session = s = hs.HapticSession(self.doc)
        print("report view:\n  " + "\n  ".join(s.part_reports))
        return s

    def test_each_part_is_said_once_with_its_back_end_and_why(self):
        s = self.open_session()
        self.assertEqual(s.part_reports, [
            "Cylinder: analytic: a recognised cylinder, in closed form; exact: valid B-rep",
            "Block: exact: valid B-rep"])
        self.assertEqual(s.messages, [])
        info = s.core.part_info(1)
        self.assertEqual((info["backend"], info["backend_reason"]), ("exact", "exact: valid B-rep"))
        self.assertGreater(info["load_s"], 0)
        self.assertEqual(s.core.snapshot()["backends"], [
            ("analytic", "analytic: a recognised cylinder, in closed form; exact: valid B-rep"),
            ("exact", "exact: valid B-rep")])

    def test_a_part_whose_outline_crosses_itself_loads_on_the_mesh_and_says_so(self):
        # FreeCAD displays it; isValid() is false (its top and bottom wires cross themselves).
        V = App.Vector
        outline = Part.makePolygon([V(10, 10, 0), V(0, 10, 0), V(0, 0, 0), V(-1, -1, 0), V(-1, 0, 0), V(0, -1, 0),
                                    V(10, -1, 0), V(10, 10, 0)])
        loop = Part.Face(outline).extrude(V(0, 0, 5))
        self.assertFalse(loop.isValid())
        self.add("Loop", loop, 0)
        s = self.open_session()
        self.assertEqual([r.obj.Name for r in s.parts], ["Cylinder", "Block", "Loop"])
        self.assertEqual(s.messages, [])   # loaded, not skipped
        said = [r for r in s.part_reports if r.startswith("Loop: ")]
        self.assertEqual(len(said), 1, s.part_reports)
        self.assertRegex(said[0], r"^Loop: mesh 0\.01 mm: self-intersecting wire in face \d+ \(not healable\); "
                                  r"the exact back end would answer wrongly there$")
        backend, reason = s.core.snapshot()["backends"][2]
        self.assertEqual(backend, "mesh")
        self.assertEqual("Loop: " + reason, said[0])

    def test_a_compound_of_overlapping_solids_is_one_part_with_its_overlap_said(self):
        touching = Part.makeCompound([Part.makeBox(10, 10, 10), Part.makeBox(10, 10, 10, App.Vector(10, 0, 0))])
        overlapping = Part.makeCompound([Part.makeBox(10, 10, 10), Part.makeBox(10, 10, 10, App.Vector(5, 5, 5))])
        self.add("Touching", touching, 0)
        self.add("Overlapping", overlapping, 100)
        s = self.open_session()
        self.assertEqual([r.obj.Name for r in s.parts], ["Cylinder", "Block", "Touching", "Overlapping"])
        self.assertIn("Touching: exact: valid B-rep", s.part_reports)
        self.assertFalse([r for r in s.part_reports if r.startswith("Touching: ") and "overlap" in r], s.part_reports)
        said = [r for r in s.part_reports if r.startswith("Overlapping: ") and "overlap" in r]
        self.assertEqual(len(said), 1, s.part_reports)
        self.assertIn("solids 1 and 2 overlap by 125 mm^3", said[0])
        # One rigid part: the two solids' volumes, the overlap counted twice.
        self.assertAlmostEqual(s.core.part_info(3)["volume_mm3"], 2000.0, delta=1e-6)

    def test_the_as1_assembly_read_as_one_shape_is_one_part(self):
        shape = Part.Shape()
        shape.read(os.path.join(os.environ.get("HG_TEST_DATA_DIR", ""), "as1-oc-214.stp"))
        self.assertEqual(len(shape.Solids), 18)
        self.add("AS1", shape, 0)
        s = self.open_session()
        self.assertEqual([r.obj.Name for r in s.parts], ["Cylinder", "Block", "AS1"])
        self.assertIn("AS1: exact: valid B-rep", s.part_reports)
        self.assertAlmostEqual(s.core.part_info(2)["volume_mm3"], shape.Volume, delta=1e-6 * shape.Volume)


class ForceParameters(unittest.TestCase):
    """The force parameters of the preferences page reach the core at start()."""

    setUp = HapticGraspDocument.setUp
    make_session = HapticGraspDocument.make_session

    def tearDown(self):
        group = App.ParamGet(hs.PARAMETER_PATH)
        for key in hs.PARAMETER_KEYS:
            group.RemFloat(key)
        HapticGraspDocument.tearDown(self)

    def test_the_defaults_are_the_papers_and_the_cores(self):
        stored = hs.stored_parameters()
        self.assertEqual({k: stored[k] for k in ("K_c", "B_c", "K_g", "B_g")},
                         {"K_c": 130.0, "B_c": 100.0, "K_g": 1000.0, "B_g": 800.0})
        self.assertEqual(stored, core.Session().parameters())
        self.assertEqual(stored["d_h"], 0.002)

    def squeeze_force(self, **stored):
        """The grasping force felt while the demo hand holds its squeeze (no lift)."""
        hs.store_parameters(stored)
        s = self.make_session(lift=False)
        s.start()
        self.assertEqual(s.core.parameters(), hs.stored_parameters())
        forces = []

        def record(snap):
            if snap["state"] == "GRASP" and 0.75 <= snap["time_s"] <= 0.95:
                forces.append(snap["grasp_force_n"])

        run(s, 0.95, on_tick=record)
        s.stop()
        self.assertTrue(forces, "never saw GRASP during the squeeze")
        return sum(forces) / len(forces)

    def test_a_stiffer_grasp_spring_from_the_preferences_squeezes_harder(self):
        # Soft springs: the demo squeeze with the paper's K_g already reaches the device's
        # force limit (10 N), where a stiffer spring could not be told apart.
        soft = self.squeeze_force(K_g=40.0)
        self.session.core.stop()
        stiff = self.squeeze_force(K_g=120.0)
        print("grasping force: K_g 40 -> %.2f N, K_g 120 -> %.2f N" % (soft, stiff))
        self.assertGreater(soft, 0.5)
        self.assertLess(stiff, 9.5)   # below the saturation
        self.assertAlmostEqual(stiff / soft, 3.0, delta=0.3)   # F = K_g sqrt(d) at rest

    def test_a_bad_value_raises_value_error_naming_the_key(self):
        hs.store_parameters({"K_g": -5.0})
        s = self.make_session()
        with self.assertRaises(ValueError) as caught:
            s.start()
        self.assertIn("K_g", str(caught.exception))
        self.assertFalse(s.running)
        for bad, key in (({"B_c": float("nan")}, "B_c"), ({"K_ox": "stiff"}, "K_ox"), ({"Q": 1.0}, "Q")):
            with self.assertRaises(ValueError) as caught:
                core.Session().set_parameters(bad)
            self.assertIn(key, str(caught.exception))
        with self.assertRaises(ValueError) as caught:   # explicit parameters: the same check
            s.start(parameters={"d_h": -1e-3})
        self.assertIn("d_h", str(caught.exception))


class MouseHandGeometry(unittest.TestCase):
    """The mouse-and-keyboard hand, pure Python."""

    def test_moves_in_the_view_plane_as_computed(self):
        from HapticGrasp.mouse_hand import MouseHand
        hand = MouseHand(centre_mm=(10.0, 20.0, 30.0), grip_mm=40.0)
        right, up = (0.0, 1.0, 0.0), (0.0, 0.0, 2.0)   # up not unit: normalised
        hand.move_in_view_plane(10, -4, right, up, 0.5)
        self.assertEqual(hand.centre, (10.0, 25.0, 28.0))
        index, thumb, wrist = hand.tick(0.0)
        self.assertEqual(index, (10.0, 45.0, 28.0))   # along the view's right vector
        self.assertEqual(thumb, (10.0, 5.0, 28.0))
        self.assertEqual(wrist, (10.0, 25.0, 128.0))  # above, along the view's up vector

    def test_wheel_moves_along_the_view_direction(self):
        from HapticGrasp.mouse_hand import MouseHand
        hand = MouseHand(centre_mm=(0.0, 0.0, 0.0))
        hand.wheel(3, (0.0, 0.0, -4.0), 5.0)
        self.assertEqual(hand.centre, (0.0, 0.0, -15.0))
        hand.wheel(-1, (0.0, 0.0, -1.0), 5.0)
        self.assertEqual(hand.centre, (0.0, 0.0, -10.0))

    def test_pinch_closes_the_grip_over_time_and_release_opens_it(self):
        from HapticGrasp.mouse_hand import MouseHand
        hand = MouseHand(grip_mm=60.0, min_grip_mm=10.0, rate_mm_s=40.0)
        hand.pinch(True)
        hand.tick(0.5)
        self.assertAlmostEqual(hand.grip, 40.0)
        index, thumb, _ = hand.tick(0.25)
        self.assertAlmostEqual(hand.grip, 30.0)
        self.assertAlmostEqual(index[0] - thumb[0], 30.0)
        hand.tick(10.0)
        self.assertAlmostEqual(hand.grip, 10.0)        # not below the minimum
        hand.pinch(False)
        hand.tick(0.5)
        self.assertAlmostEqual(hand.grip, 30.0)
        hand.tick(10.0)
        self.assertAlmostEqual(hand.grip, 60.0)        # open again, not beyond


class MouseHandSession(unittest.TestCase):
    """A session driven by MouseHand ticks, as the GUI's timer does (no GUI)."""

    setUp = HapticGraspDocument.setUp
    tearDown = HapticGraspDocument.tearDown

    RIGHT, UP, INTO = (1.0, 0.0, 0.0), (0.0, 0.0, 1.0), (0.0, 1.0, 0.0)   # the front view

    def drive(self, s, hand, steps, period=0.02):
        """steps: [(duration_s, action)], action(hand, dt) called every tick; the hand is
        fed every tick and the document ticked. Returns the states seen."""
        return self.drive_until(s, hand, steps, None, period)[0]

    def drive_until(self, s, hand, steps, done, period=0.02):
        """drive(), stopping (and no longer feeding the hand) as soon as done() is true
        (done None: never). Returns (states, done reached)."""
        states = []
        for duration, action in steps:
            end = time.monotonic() + duration
            last = time.monotonic()
            while time.monotonic() < end and s.running:
                now = time.monotonic()
                dt, last = now - last, now
                if action:
                    action(hand, dt)
                s.set_hand(*hand.tick(dt))
                state = s.tick()["state"]
                if not states or states[-1] != state:
                    states.append(state)
                if done is not None and done():
                    return states, True
                time.sleep(period)
        return states, False

    def mouse_session(self):
        from HapticGrasp.mouse_hand import MouseHand
        self.session = s = hs.HapticSession(self.doc)
        s.use_hand_input(hold_s=0.5)
        box = self.cylinder.Shape.BoundBox
        diameter = box.XLength
        start = box.Center + App.Vector(0, 0, 100.0)          # above the part, outside
        hand = MouseHand(centre_mm=start, grip_mm=diameter + 40.0, min_grip_mm=diameter - 1.0,
                         rate_mm_s=60.0, right=self.RIGHT, up=self.UP, view_dir=self.INTO)
        return s, hand

    @staticmethod
    def move(dx_px, dy_px, duration, mm_per_px=1.0):
        """Mouse motion spread over `duration` seconds of ticks."""
        left = [1.0]   # the fraction of the motion still to come

        def action(hand, dt):
            u = min(left[0], dt / duration)
            left[0] -= u
            hand.move_in_view_plane(dx_px * u, dy_px * u, MouseHandSession.RIGHT, MouseHandSession.UP, mm_per_px)
        return action

    def test_approach_pinch_lift_release_moves_the_part_up_in_one_undo_step(self):
        before = App.Placement(self.cylinder.Placement)
        s, hand = self.mouse_session()
        target_z = hand.centre[2] - 100.0
        s.start()
        states = self.drive(s, hand, [(0.1, None), (0.6, self.move(0, -100, 0.5)), (0.2, None)])
        self.assertAlmostEqual(hand.centre[2], target_z, delta=1e-6)
        hand.pinch(True)
        states += self.drive(s, hand, [(1.2, None)])
        self.assertIn("GRASP", states)
        lift_from = hand.centre[2]
        states += self.drive(s, hand, [(0.6, self.move(0, 50, 0.5)), (0.3, None)])
        self.assertAlmostEqual(hand.centre[2], lift_from + 50.0, delta=1e-6)
        self.assertIn("MANIPULATE", states)
        hand.pinch(False)
        states += self.drive(s, hand, [(1.0, None)])
        s.stop()
        self.assertEqual(states[-1], "FREE", states)
        moved = self.cylinder.Placement.Base - before.Base
        print("mouse hand: moved by (%.3f, %.3f, %.3f) mm, states %s" % (moved.x, moved.y, moved.z, states))
        self.assertAlmostEqual(moved.x, 0.0, delta=1.0)
        self.assertAlmostEqual(moved.y, 0.0, delta=1.0)
        self.assertAlmostEqual(moved.z, 50.0, delta=2.0)
        self.assertEqual(self.doc.UndoNames, ["Haptic move Cylinder"])

    def test_cancel_mid_move_restores_the_placement_and_leaves_no_undo_entry(self):
        before = App.Placement(self.cylinder.Placement)
        s, hand = self.mouse_session()
        hand.centre = tuple(self.cylinder.Shape.BoundBox.Center)   # fingers open around it
        s.start()
        hand.pinch(True)
        states = self.drive(s, hand, [(1.2, None), (0.6, self.move(0, 50, 0.5))])
        self.assertIn("MANIPULATE", states)
        self.assertIsNotNone(s.active)
        self.assertGreater((self.cylinder.Placement.Base - before.Base).Length, 5.0)
        s.cancel()
        self.assertFalse(s.running)
        self.assertIsNone(s.active)
        self.assertEqual(s.aborted, 1)
        self.assertEqual(s.moves, 0)
        self.assertTrue(hs.same_placement(self.cylinder.Placement, before), self.cylinder.Placement)
        self.assertEqual(self.doc.UndoCount, 0)
        self.assertEqual(len(s.messages), 1, s.messages)
        self.assertIn("cancelled", s.messages[0])
        self.assertIn("Cylinder", s.messages[0])

    def test_closing_the_panel_mid_move_cancels_like_esc(self):
        # The panel's Close / the dialog's reject go through panel.close_session(): the real
        # controller, without a GUI (no timer, overlay or Coin callbacks in freecadcmd).
        from HapticGrasp import gui as hgui
        from HapticGrasp import panel as hpanel
        controller = hgui._HapticGraspController
        before = App.Placement(self.cylinder.Placement)
        s, hand = self.mouse_session()
        hand.centre = tuple(self.cylinder.Shape.BoundBox.Center)   # fingers open around it
        s.start()
        hand.pinch(True)
        states = self.drive(s, hand, [(1.2, None), (0.6, self.move(0, 50, 0.5))])
        self.assertIn("MANIPULATE", states)
        self.assertIsNotNone(s.active)
        self.assertGreater((self.cylinder.Placement.Base - before.Base).Length, 5.0)

        class PanelStub:
            running = None

            def set_running(self, running):
                self.running = running

        stub = PanelStub()
        controller.session, controller.panel = s, stub
        try:
            hpanel.close_session(controller)
        finally:
            controller.session = controller.panel = None
        self.assertIs(stub.running, False)
        self.assertFalse(s.running)
        self.assertIsNone(s.active)
        self.assertEqual(s.aborted, 1)
        self.assertEqual(s.moves, 0)
        self.assertTrue(hs.same_placement(self.cylinder.Placement, before), self.cylinder.Placement)
        self.assertEqual(self.doc.UndoCount, 0)
        self.assertEqual(len(s.messages), 1, s.messages)
        self.assertIn("cancelled", s.messages[0])


class SimulatedArmSession(unittest.TestCase):
    """The "Simulated arm (mouse + keyboard)" device without the GUI: a MouseHand (as the
    GUI's mouse events move it) is the TARGET of the simulated operator who drives the
    simulated master arm; the grasp sees the arm's fingertips. The arm is placed above the
    sample block (100 x 60 x 40 mm), its grip axis across the block's 60 mm (y)."""

    setUp = HapticGraspDocument.setUp
    tearDown = HapticGraspDocument.tearDown
    drive = MouseHandSession.drive
    drive_until = MouseHandSession.drive_until
    move = staticmethod(MouseHandSession.move)

    GRASP_BELOW_TOP_MM = 25.0   # the grasp height under the block's top (the core's bench)

    def arm_session(self, hold_s=0.5):
        from HapticGrasp import mouse_hand
        self.session = s = hs.HapticSession(self.doc)
        rest = s.use_simulated_arm(self.block, hold_s=hold_s)
        self.assertEqual(s.core.device_name, "simulated arm")
        self.assertTrue(s.core.device_force_output)
        box = self.block.Shape.BoundBox
        self.assertAlmostEqual(rest["grip_axis"][1], 1.0, places=9)   # across the block's 60 mm
        centre = (App.Vector(*rest["index"]) + App.Vector(*rest["thumb"])) * 0.5
        self.assertAlmostEqual((centre - App.Vector(box.Center.x, box.Center.y, box.ZMax + 30.0)).Length, 0.0,
                               places=6)
        hand = mouse_hand.for_arm(rest, box.YLength, right=MouseHandSession.RIGHT, up=MouseHandSession.UP,
                                  view_dir=MouseHandSession.INTO, rate_mm_s=150.0)
        return s, hand, box

    def approach_and_pinch(self, s, hand, box):
        """Down from the rest pose to the grasp height, open around the block; pinch."""
        down = hand.centre[2] - (box.ZMax - self.GRASP_BELOW_TOP_MM)
        states = self.drive(s, hand, [(0.3, None), (0.6, self.move(0, -down, 0.5)), (0.4, None)])
        hand.pinch(True)
        states += self.drive(s, hand, [(1.0, None)])
        return states

    def test_the_arm_grasps_the_block_with_its_own_fingertips_and_lifts_it(self):
        before = App.Placement(self.block.Placement)
        s, hand, box = self.arm_session()
        s.set_hand(*hand.tick(0.0))   # the arm device exists before start(): fed at once
        s.start()
        states = self.approach_and_pinch(s, hand, box)
        self.assertIn("GRASP", states)
        # The grasp sees the ARM's fingertips: they stop at the block's sides while the
        # pinched target has its fingertips 5 mm apart, deep inside the block.
        snap = s.core.snapshot()
        index, thumb = App.Vector(*snap["hand"][0]), App.Vector(*snap["hand"][1])
        target = s.target
        print("arm: fingertips %.1f mm apart on the block (target %.1f mm apart)"
              % ((index - thumb).Length, (target[0] - target[1]).Length))
        self.assertGreater((index - thumb).Length, 55.0)   # the block's 60 mm, the fingertips a little in
        self.assertLess((index - thumb).Length, 65.0)
        self.assertLess((target[0] - target[1]).Length, 10.0)   # closed: index 15, thumb 40 mm inside
        states += self.drive(s, hand, [(0.8, self.move(0, 50, 0.6)), (0.3, None)])
        self.assertIn("MANIPULATE", states)
        raised = self.block.Placement.Base.z - before.Base.z
        s.stop()
        print("simulated arm: target lifted 50 mm, block raised %.1f mm in %d move(s), states %s"
              % (raised, s.moves, states))
        self.assertGreater(raised, 25.0)
        self.assertGreaterEqual(s.moves, 1)
        self.assertEqual(set(self.doc.UndoNames), {"Haptic move Block"})
        for _ in range(self.doc.UndoCount):
            self.doc.undo()
        self.assertTrue(hs.same_placement(self.block.Placement, before), self.block.Placement)

    # The drops (released at d_h, 6-8 undo steps) were the arm displaying the grip force twice;
    # since that fix the block is carried in one move. The carried block turned ~90-150 deg
    # about the grip axis (the operator's hand orientation was free; the arm's wrist point
    # lies ~115 mm from the grip centre along the finger line and only 25-50 mm off it, so
    # eq 17's h2 swings around h1 as the fingers yaw): centre moved (64, -5, -3) mm, turned
    # 93 deg, Base (82, -4, 17), ended THUMB CONTACT. Since the operator holds the hand's
    # orientation while grasping: centre (61, 0, -14) mm, turned 22 deg (~9 deg during the
    # carry, the rest while the thumb opens), Base (66.4, 0.9, -8.4), ends FREE in one undo
    # step (3 runs alike), but the block hung ~10 mm low under the displayed weight and the
    # residual turn moved Base past 6 mm. With the grasp's wrist point x_w moved ~100 mm off
    # the finger line (the URDF's "hand_reference", behind the back of the hand): turned
    # 2.8 deg, Base (61.5, 7.8, -9.3) -- the arm's give under the weight, now also along the
    # grip axis. With the operator also making up for that give while grasping (the device's
    # aim): Base (58.5, 0.7, 1.7), turned 2.8 deg, one move, ends FREE.
    def test_approach_pinch_lift_move_put_down_open_moves_the_block_in_one_undo_step(self):
        before = App.Placement(self.block.Placement)
        s, hand, box = self.arm_session()
        s.set_hand(*hand.tick(0.0))
        s.start()
        states = self.approach_and_pinch(s, hand, box)
        lift, carry = 50.0, 60.0
        states += self.drive(s, hand, [(0.8, self.move(0, lift, 0.6)), (0.4, None)])
        states += self.drive(s, hand, [(0.9, self.move(carry, 0, 0.7)), (0.4, None)])
        states += self.drive(s, hand, [(0.8, self.move(0, -lift, 0.6)), (0.5, None)])
        hand.pinch(False)
        states += self.drive(s, hand, [(0.8, None), (0.6, self.move(0, 40, 0.5))])
        s.stop()
        moved = self.block.Placement.Base - before.Base
        turn = self.block.Placement.Rotation.multiply(before.Rotation.inverted())
        print("simulated arm: moved the block by (%.3f, %.3f, %.3f) mm for (%.1f, 0, 0), turned %.1f deg about "
              "(%.2f, %.2f, %.2f), %d move(s), states %s"
              % (moved.x, moved.y, moved.z, carry, math.degrees(turn.Angle), turn.Axis.x, turn.Axis.y, turn.Axis.z,
                 s.moves, states))
        self.assertEqual(states[-1], "FREE", states)
        self.assertAlmostEqual(moved.x, carry, delta=6.0)
        self.assertAlmostEqual(moved.y, 0.0, delta=6.0)
        self.assertAlmostEqual(moved.z, 0.0, delta=6.0)
        self.assertEqual(self.doc.UndoNames, ["Haptic move Block"])
        self.doc.undo()
        self.assertTrue(hs.same_placement(self.block.Placement, before), self.block.Placement)

    def test_a_target_that_goes_silent_mid_move_aborts_and_restores_the_block(self):
        before = App.Placement(self.block.Placement)
        s, hand, box = self.arm_session(hold_s=0.05)   # silent 50 ms after the last target
        s.set_hand(*hand.tick(0.0))
        s.start()
        states = self.approach_and_pinch(s, hand, box)

        def carrying():
            return s.active is not None and (self.block.Placement.Base - before.Base).Length > 3.0

        more, carried = self.drive_until(s, hand, [(0.8, self.move(0, 50, 0.6)), (0.3, None)], carrying)
        states += more
        self.assertTrue(carried, states)
        deadline = time.monotonic() + 3.0   # the target is no longer set: silence after 50 ms
        while s.running and time.monotonic() < deadline:
            s.tick()
            time.sleep(TICK_S)
        print("silent target: states %s, messages %s, fault %s, moves %d" % (states, s.messages, s.fault, s.moves))
        self.assertFalse(s.running)
        self.assertEqual(s.aborted, 1)
        self.assertIsNone(s.active)
        self.assertEqual(self.doc.UndoCount, s.moves)   # the aborted move left no undo step
        self.assertEqual(len(s.messages), 1, s.messages)
        self.assertIn("device fault (silent)", s.messages[0])
        self.assertIn("Block", s.messages[0])
        for _ in range(self.doc.UndoCount):
            self.doc.undo()
        self.assertTrue(hs.same_placement(self.block.Placement, before), self.block.Placement)


def _report(report_id, *values):
    """A SpaceMouse-style report: the ID, then int16 little-endian values."""
    import struct
    return bytes([report_id]) + struct.pack("<%dh" % len(values), *values)


class HidDeviceSession(unittest.TestCase):
    """SpaceMouse and HID layout devices through the module's in-process fake transport
    (core._use_fake_hid(), test only: this kernel cannot make virtual HID devices); the
    servo thread reads them while the test feeds reports and ticks the document."""

    PATH = "/dev/hidraw-test0"

    def setUp(self):
        HapticGraspDocument.setUp(self)
        self.feed = core._use_fake_hid()

    def tearDown(self):
        core._use_real_hid()
        HapticGraspDocument.tearDown(self)

    def add_spacemouse(self):
        self.feed.add_device(self.PATH, 0x046D, 0xC626, "SpaceNavigator")

    def hold(self, s, seconds, report=None, every=0.05):
        """Ticks the document for `seconds`, sending `report` every `every` s (a deflected
        cap repeats its report). Returns the states seen."""
        states = []
        end = time.monotonic() + seconds
        sent = 0.0
        while time.monotonic() < end and s.running:
            if report is not None and time.monotonic() - sent >= every:
                self.feed.queue_report(self.PATH, report)
                sent = time.monotonic()
            state = s.tick()["state"]
            if not states or states[-1] != state:
                states.append(state)
            time.sleep(TICK_S)
        return states

    def spacemouse_session(self):
        self.add_spacemouse()
        self.session = s = hs.HapticSession(self.doc)
        box = self.cylinder.Shape.BoundBox
        # The grip (along y) open around the cylinder's length, closing fully, as the GUI does.
        s.use_spacemouse("", start=box.Center, open_mm=box.YLength + 40.0, closed_mm=0.0)
        return s

    def test_the_attached_devices_are_listed_with_their_back_end(self):
        self.add_spacemouse()
        self.feed.add_device("/dev/hidraw-test1", 0x1209, 0x0001, "FF stick")
        self.feed.add_device("/dev/hidraw-test2", 0x1234, 0x5678, "keyboard")
        devices, errors = hs.list_devices()
        self.assertEqual(errors, [])
        self.assertEqual([(d["path"], d["backend"]) for d in devices],
                         [(self.PATH, "spacemouse"), ("/dev/hidraw-test1", "layout"), ("/dev/hidraw-test2", "none")])
        self.assertEqual(devices[0]["model"], "SpaceNavigator")
        self.assertTrue(devices[1]["layout"].endswith("ff_joystick_3dof.json"), devices[1])
        from HapticGrasp import panel as hpanel
        self.assertEqual([key for key, _, _ in hpanel.hid_choices(devices)],
                         ["spacemouse:" + self.PATH, "hid:/dev/hidraw-test1"])
        self.assertIn("No SpaceMouse or HID device attached", hpanel.hid_message([], []))

    def test_a_spacemouse_grasps_lifts_and_releases_the_part_in_one_undo_step(self):
        before = App.Placement(self.cylinder.Placement)
        s = self.spacemouse_session()
        self.assertIn("SpaceNavigator", s.core.device_name)
        self.assertFalse(s.core.device_force_output)   # input only: forces computed, not displayed
        s.start()
        states = self.hold(s, 0.5)          # at rest, silent: not a fault
        self.assertEqual(s.fault, "none")
        self.assertEqual(states, ["FREE"])
        start = s.hand_at(0)[2]             # the wrist, from the snapshot
        states += self.hold(s, 1.0, _report(3, 1))            # button 1: pinch
        self.assertIn("GRASP", states)
        states += self.hold(s, 0.7, _report(1, 0, 0, -175))   # cap pulled up: the hand rises
        states += self.hold(s, 0.3, _report(1, 0, 0, 0))      # let go of the cap
        self.assertIn("MANIPULATE", states)
        lifted = s.hand_at(0)[2].z - start.z
        states += self.hold(s, 1.0, _report(3, 2))            # button 2: open
        s.stop()
        self.assertEqual(states[-1], "FREE", states)
        self.assertEqual(s.fault, "none")
        moved = self.cylinder.Placement.Base - before.Base
        print("spacemouse: hand lifted %.1f mm, part moved by (%.3f, %.3f, %.3f) mm, states %s"
              % (lifted, moved.x, moved.y, moved.z, states))
        self.assertGreater(lifted, 20.0)
        self.assertGreater(moved.z, 10.0)
        self.assertAlmostEqual(moved.x, 0.0, delta=2.0)
        self.assertAlmostEqual(moved.y, 0.0, delta=2.0)
        self.assertEqual(self.doc.UndoNames, ["Haptic move Cylinder"])

    def test_twisting_the_spacemouse_cap_turns_the_part_in_one_undo_step(self):
        before = App.Placement(self.cylinder.Placement)
        s = self.spacemouse_session()
        s.start()
        states = self.hold(s, 1.0, _report(3, 1))                 # pinch
        states += self.hold(s, 0.5, _report(1, 0, 0, -175))       # lift
        states += self.hold(s, 0.2, _report(1, 0, 0, 0))
        self.assertIn("MANIPULATE", states)
        states += self.hold(s, 0.5, _report(2, 0, 0, -175))       # twist the cap about z
        states += self.hold(s, 0.3, _report(2, 0, 0, 0))
        self.assertEqual(states[-1], "MANIPULATE", states)
        states += self.hold(s, 1.0, _report(3, 2))                # open
        s.stop()
        self.assertEqual(states[-1], "FREE", states)
        turn = self.cylinder.Placement.Rotation.multiply(before.Rotation.inverted())   # absolute frame
        axis = turn.Axis
        angle = turn.Angle if turn.Angle <= math.pi else turn.Angle - 2 * math.pi   # FreeCAD gives [0, 2 pi)
        degrees = math.degrees(angle) * (1 if axis.z >= 0 else -1)   # about +z
        print("spacemouse twist: the part turned %.1f deg about (%.2f, %.2f, %.2f)" % (degrees, axis.x, axis.y, axis.z))
        self.assertGreater(degrees, 5.0)                          # counter-clockwise seen from above
        self.assertGreater(abs(axis.z), 0.9)                      # about the vertical
        self.assertEqual(self.doc.UndoNames, ["Haptic move Cylinder"])

    def test_a_spacemouse_unplugged_mid_move_aborts_and_restores_the_placement(self):
        before = App.Placement(self.cylinder.Placement)
        s = self.spacemouse_session()
        s.start()
        states = self.hold(s, 1.0, _report(3, 1))
        states += self.hold(s, 0.5, _report(1, 0, 0, -175))
        self.assertIn("MANIPULATE", states)
        self.assertIsNotNone(s.active)
        self.feed.remove_device(self.PATH)   # read errors from now on
        self.hold(s, 3.0)
        self.assertFalse(s.running)
        self.assertEqual(s.aborted, 1)
        self.assertTrue(hs.same_placement(self.cylinder.Placement, before), self.cylinder.Placement)
        self.assertEqual(self.doc.UndoCount, 0)
        self.assertIn("device fault (silent)", s.messages[-1])

    def test_picking_a_spacemouse_with_none_attached_says_so_and_keeps_the_device(self):
        self.session = s = hs.HapticSession(self.doc)
        s.use_hand_input()
        with self.assertRaises(core.DeviceError) as caught:
            s.use_spacemouse("")
        self.assertIsInstance(caught.exception, RuntimeError)
        self.assertIn("no SpaceMouse attached", str(caught.exception))
        self.assertEqual(s.core.device_name, "hand input")
        with self.assertRaises(RuntimeError) as caught:
            s.use_spacemouse("/dev/hidraw-none")
        self.assertIn("/dev/hidraw-none", str(caught.exception))
        self.assertEqual(s.core.device_name, "hand input")
        self.assertEqual(self.doc.UndoCount, 0)

    def test_a_hid_layout_device_places_its_hand_at_the_origin_given(self):
        self.feed.add_device(self.PATH, 0x1209, 0x0001, "FF stick")
        layout = os.path.join(hs.layout_dirs()[0], "ff_joystick_3dof.json")
        self.session = s = hs.HapticSession(self.doc)
        origin = self.cylinder.Shape.BoundBox.Center + App.Vector(0, 0, 200)
        s.use_hid(layout, "", origin=origin)
        self.assertTrue(s.core.device_name.startswith("Generic 3-DOF force-feedback joystick"), s.core.device_name)
        self.assertTrue(s.core.device_force_output)
        # wrist (10, -5, 0) mm on the stick (+100 mm of bias in z), trigger released
        report = _report(1, 1000, -500, 0) + bytes([0, 0, 0])
        self.feed.queue_report(self.PATH, report)   # streaming from the start (50 ms watchdog)
        s.start()
        self.hold(s, 0.3, report, every=0.01)
        wrist = s.hand_at(0)[2]
        s.stop()
        expected = origin + App.Vector(10, -5, 100)
        self.assertLess((wrist - expected).Length, 1e-6, (wrist, expected))

    def test_a_bad_layout_is_refused_naming_the_field(self):
        import json
        import tempfile
        layout = json.load(open(os.path.join(hs.layout_dirs()[0], "ff_joystick_3dof.json")))
        layout["fields"][1]["offset"] = 99
        with tempfile.NamedTemporaryFile("w", suffix=".json", delete=False) as f:
            json.dump(layout, f)
        self.feed.add_device(self.PATH, 0x1209, 0x0001, "FF stick")
        self.session = s = hs.HapticSession(self.doc)
        try:
            with self.assertRaises(ValueError) as caught:
                s.use_hid(f.name)
        finally:
            os.unlink(f.name)
        self.assertIn("fields[1]", str(caught.exception))
        self.assertEqual(s.core.device_name, "none")
