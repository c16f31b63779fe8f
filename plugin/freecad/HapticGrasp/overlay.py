"""3D overlay of a running haptic session: Coin nodes (pivy) added to the active view's
scene graph, never document objects (no undo, nothing saved). GUI thread only.

  - fingertip spheres (index, thumb, and up to three more for a multi-finger device) and a
    wrist marker (a cube), coloured by grasp state;
  - force arrows from each fingertip, length = force * ARROW_MM_PER_N (hidden while the
    force is zero or unknown);
  - the grasp frame: three short lines (x red, y green, z blue) at the fingertips'
    midpoint, turned with the grasped part;
  - with the simulated arm, the operator's target (the mouse hand) as two faint, smaller
    spheres: the arm's fingertips (the hand the servo loop used) lag and stop at surfaces;
  - part-to-part clearance: a line from the carried part to the nearest point of the
    nearest other part, green while clear, red in contact or interference (hidden when no
    part is near).
"""
import FreeCAD as App

STATE_COLOURS = {
    "FREE": (0.6, 0.6, 0.6),
    "INDEX CONTACT": (1.0, 0.8, 0.1),
    "THUMB CONTACT": (1.0, 0.8, 0.1),
    "GRASP": (1.0, 0.45, 0.0),
    "MANIPULATE": (0.1, 0.8, 0.2),
}
FAULT_COLOUR = (0.9, 0.1, 0.1)
ROOT_NAME = "HapticGraspOverlay"
FINGERTIP_RADIUS_MM = 4.0
WRIST_SIZE_MM = 10.0
ARROW_MM_PER_N = 5.0
FRAME_LENGTH_MM = 25.0
EXTRA_FINGERTIPS = 3   # fingertips 2..4 of a multi-finger device, shown only when it has them
TARGET_RADIUS_MM = 2.5
CLEAR_COLOUR = (0.1, 0.8, 0.3)
TOUCH_COLOUR = (0.9, 0.1, 0.1)
TOUCH_MM = 0.01   # nearer than this: in contact


class HapticOverlay:
    def __init__(self, view):
        from pivy import coin
        self.coin = coin
        self.view = view
        self.graph = view.getSceneGraph()
        self.root = coin.SoAnnotation()   # drawn on top: fingertips stay visible at contact
        self.root.setName(ROOT_NAME)
        self.state_material = coin.SoMaterial()
        self.root.addChild(self.state_material)
        self.fingertips = [self._fingertip(name)[1] for name in ("Index", "Thumb")]
        self.extra = [self._fingertip("Finger%d" % (k + 2)) for k in range(EXTRA_FINGERTIPS)]
        for switch, _move in self.extra:
            switch.whichChild = coin.SO_SWITCH_NONE
        wrist = coin.SoSeparator()
        wrist.setName(ROOT_NAME + "Wrist")
        self.wrist = coin.SoTranslation()
        cube = coin.SoCube()
        cube.width = cube.height = cube.depth = WRIST_SIZE_MM
        wrist.addChild(self.wrist)
        wrist.addChild(cube)
        self.root.addChild(wrist)
        self.arrows = [self._arrow(name) for name in ("Index", "Thumb")]
        self.extra_arrows = [self._arrow("Finger%d" % (k + 2)) for k in range(EXTRA_FINGERTIPS)]
        # grasp frame: three lines, one colour each
        frame = coin.SoSeparator()
        frame.setName(ROOT_NAME + "GraspFrame")
        colours = coin.SoMaterial()
        colours.diffuseColor.setValues(0, 3, [(1, 0, 0), (0, 0.8, 0), (0, 0, 1)])
        colours.emissiveColor.setValues(0, 3, [(1, 0, 0), (0, 0.8, 0), (0, 0, 1)])
        binding = coin.SoMaterialBinding()
        binding.value = coin.SoMaterialBinding.PER_PART
        style = coin.SoDrawStyle()
        style.lineWidth = 2
        self.frame_coords = coin.SoCoordinate3()
        self.frame_coords.point.setValues(0, 6, [(0, 0, 0)] * 6)
        lines = coin.SoLineSet()
        lines.numVertices.setValues(0, 3, [2, 2, 2])
        for node in (colours, binding, style, self.frame_coords, lines):
            frame.addChild(node)
        self.root.addChild(frame)
        # the arm operator's target: faint spheres in a switch (hidden without a target)
        self.target_switch = coin.SoSwitch()
        self.target_switch.setName(ROOT_NAME + "Target")
        sep = coin.SoSeparator()
        material = coin.SoMaterial()
        material.diffuseColor = (0.6, 0.6, 0.9)
        material.transparency = 0.6
        sep.addChild(material)
        self.targets = []
        for _name in ("Index", "Thumb"):
            tip = coin.SoSeparator()
            move = coin.SoTranslation()
            sphere = coin.SoSphere()
            sphere.radius = TARGET_RADIUS_MM
            tip.addChild(move)
            tip.addChild(sphere)
            sep.addChild(tip)
            self.targets.append(move)
        self.target_switch.addChild(sep)
        self.target_switch.whichChild = coin.SO_SWITCH_NONE
        self.root.addChild(self.target_switch)
        self._add_clearance()
        self.graph.addChild(self.root)
        self.update("FREE")

    def _add_clearance(self):
        """The clearance line, in a switch (hidden until a carried part has a near neighbour)."""
        coin = self.coin
        self.clearance_switch = coin.SoSwitch()
        self.clearance_switch.setName(ROOT_NAME + "Clearance")
        sep = coin.SoSeparator()
        self.clearance_material = coin.SoMaterial()
        style = coin.SoDrawStyle()
        style.lineWidth = 3
        self.clearance_coords = coin.SoCoordinate3()
        self.clearance_coords.point.setValues(0, 2, [(0, 0, 0), (0, 0, 0)])
        line = coin.SoLineSet()
        line.numVertices.setValue(2)
        for node in (self.clearance_material, style, self.clearance_coords, line):
            sep.addChild(node)
        self.clearance_switch.addChild(sep)
        self.clearance_switch.whichChild = coin.SO_SWITCH_NONE
        self.root.addChild(self.clearance_switch)

    def show_clearance(self, contact):
        """contact: the snapshot's "contact" (None or no part near: hidden)."""
        if contact is None or contact["part"] < 0 or not contact["exact"]:
            self.clearance_switch.whichChild = self.coin.SO_SWITCH_NONE
            return
        colour = TOUCH_COLOUR if contact["clearance_mm"] < TOUCH_MM else CLEAR_COLOUR
        self.clearance_material.diffuseColor = colour
        self.clearance_material.emissiveColor = colour
        self.clearance_coords.point.setValues(0, 2, [tuple(contact["held_point"]), tuple(contact["other_point"])])
        self.clearance_switch.whichChild = self.coin.SO_SWITCH_ALL

    def _fingertip(self, name):
        """A sphere under a switch: (switch, its translation)."""
        coin = self.coin
        switch = coin.SoSwitch()
        switch.setName(ROOT_NAME + name)
        sep = coin.SoSeparator()
        move = coin.SoTranslation()
        sphere = coin.SoSphere()
        sphere.radius = FINGERTIP_RADIUS_MM
        sep.addChild(move)
        sep.addChild(sphere)
        switch.addChild(sep)
        switch.whichChild = coin.SO_SWITCH_ALL
        self.root.addChild(switch)
        return switch, move

    def _arrow(self, name):
        """A force arrow, a line and a cone at its tip, in a switch (hidden when unknown):
        (switch, line coordinates, cone transform)."""
        coin = self.coin
        switch = coin.SoSwitch()
        switch.setName(ROOT_NAME + name + "Force")
        sep = coin.SoSeparator()
        material = coin.SoMaterial()
        material.diffuseColor = (0.1, 0.4, 1.0)
        material.emissiveColor = (0.05, 0.2, 0.5)
        style = coin.SoDrawStyle()
        style.lineWidth = 3
        coords = coin.SoCoordinate3()
        coords.point.setValues(0, 2, [(0, 0, 0), (0, 0, 0)])
        line = coin.SoLineSet()
        line.numVertices.setValue(2)
        head = coin.SoTransform()
        cone = coin.SoCone()
        cone.bottomRadius = 2.0
        cone.height = 5.0
        for node in (material, style, coords, line, head, cone):
            sep.addChild(node)
        switch.addChild(sep)
        switch.whichChild = coin.SO_SWITCH_NONE
        self.root.addChild(switch)
        return switch, coords, head

    def _show_arrow(self, arrow, point, force):
        switch, coords, head = arrow
        if force is None or force.Length < 1e-9:
            switch.whichChild = self.coin.SO_SWITCH_NONE
            return
        tip = point + force * ARROW_MM_PER_N
        coords.point.setValues(0, 2, [(point.x, point.y, point.z), (tip.x, tip.y, tip.z)])
        head.translation = (tip.x, tip.y, tip.z)
        head.rotation = self.coin.SbRotation(self.coin.SbVec3f(0, 1, 0), self.coin.SbVec3f(force.x, force.y, force.z))
        switch.whichChild = self.coin.SO_SWITCH_ALL

    def attached(self):
        return self.graph is not None and self.graph.findChild(self.root) >= 0

    def update(self, state, hand=None, forces=None, frame_rotation=None, fault=False, more=(), target=None):
        """state: the grasp state; hand: (index, thumb, wrist) Vectors in mm or None;
        forces: (index, thumb) force Vectors in N or None; frame_rotation: the grasped
        part's Rotation (None: the world axes); more: (point mm, force N) Vectors of the
        fingertips after the thumb, for a multi-finger device (the others are hidden);
        target: the simulated arm operator's (index, thumb, ...) Vectors in mm, or None."""
        colour = FAULT_COLOUR if fault else STATE_COLOURS.get(state, STATE_COLOURS["FREE"])
        self.state_material.diffuseColor = colour
        self.state_material.emissiveColor = tuple(0.5 * c for c in colour)  # lit or not
        if target is None:
            self.target_switch.whichChild = self.coin.SO_SWITCH_NONE
        else:
            for move, point in zip(self.targets, target[:2]):
                move.translation = (point.x, point.y, point.z)
            self.target_switch.whichChild = self.coin.SO_SWITCH_ALL
        if hand is None:
            return
        index, thumb, wrist = hand
        for move, point in zip(self.fingertips, (index, thumb)):
            move.translation = (point.x, point.y, point.z)
        self.wrist.translation = (wrist.x, wrist.y, wrist.z)
        for arrow, point, force in zip(self.arrows, (index, thumb), forces or (None, None)):
            self._show_arrow(arrow, point, force)
        more = list(more)[:EXTRA_FINGERTIPS]
        for k, ((switch, move), arrow) in enumerate(zip(self.extra, self.extra_arrows)):
            if k < len(more):
                point, force = more[k]
                move.translation = (point.x, point.y, point.z)
                switch.whichChild = self.coin.SO_SWITCH_ALL
                self._show_arrow(arrow, point, force)
            else:
                switch.whichChild = self.coin.SO_SWITCH_NONE
                self._show_arrow(arrow, None, None)
        centre = (index + thumb) * 0.5
        rotation = frame_rotation or App.Rotation()
        points = []
        for axis in (App.Vector(1, 0, 0), App.Vector(0, 1, 0), App.Vector(0, 0, 1)):
            end = centre + rotation.multVec(axis) * FRAME_LENGTH_MM
            points += [(centre.x, centre.y, centre.z), (end.x, end.y, end.z)]
        self.frame_coords.point.setValues(0, 6, points)

    def remove(self):
        if self.graph is not None and self.graph.findChild(self.root) >= 0:
            self.graph.removeChild(self.root)
        self.graph = None
