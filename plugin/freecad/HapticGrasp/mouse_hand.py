"""A simulated hand driven by the mouse and keyboard (pure Python, no FreeCAD import).

State: the hand centre (mm, document coordinates) and the grip opening (mm, distance
between the index and thumb fingertips). The GUI feeds it from Coin events on the 3D view:
mouse motion moves the centre in the view plane, the wheel moves it along the view
direction (depth), a key held pinches (closes the grip at `rate_mm_s`), releasing the key
opens it again. tick(dt) advances the grip and returns (index_mm, thumb_mm, wrist_mm):
index and thumb on either side of the centre along the view's right vector, the wrist
`wrist_up_mm` above the centre along the view's up vector and `wrist_back_mm` behind it
(towards the viewer).

For the simulated arm (for_arm()) the hand is the arm operator's TARGET: its grip axis is
the arm's (fixed, whatever the view), its wrist keeps a fixed offset from the grip centre
(wrist_offset_mm: the arm's resting hand, levelled), and the pinch closes each fingertip
to its own offset (`closed_mm`: index, thumb along the grip axis from the centre): the
index first, the thumb once the index is well on its way (a thumb that touches first shoves
the arm's hand off the part). Closed, the index aims 15 mm and the thumb 40 mm inside the
part's sides, as in the core's servo bench (the operator lags, the thumb closes less than
the index; the arm's fingertips stop at the surfaces and squeeze).
"""


def _vec(v):
    return (float(v[0]), float(v[1]), float(v[2])) if not hasattr(v, "x") else (float(v.x), float(v.y), float(v.z))


def _add(a, b, s=1.0):
    return (a[0] + s * b[0], a[1] + s * b[1], a[2] + s * b[2])


def _unit(v):
    n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) ** 0.5
    if n == 0.0:
        raise ValueError("zero-length view vector")
    return (v[0] / n, v[1] / n, v[2] / n)


class MouseHand:
    def __init__(self, centre_mm=(0.0, 0.0, 0.0), grip_mm=60.0, min_grip_mm=0.0, max_grip_mm=None,
                 rate_mm_s=40.0, right=(1.0, 0.0, 0.0), up=(0.0, 0.0, 1.0), view_dir=(0.0, 1.0, 0.0),
                 wrist_up_mm=100.0, wrist_back_mm=0.0, grip_axis=None, wrist_offset_mm=None, tilt_mm=0.0,
                 closed_mm=None):
        self.centre = _vec(centre_mm)
        self.grip = float(grip_mm)
        self.min_grip = float(min_grip_mm)
        self.max_grip = float(grip_mm if max_grip_mm is None else max_grip_mm)
        self.rate = float(rate_mm_s)
        self.closing = False
        self.wrist_up = float(wrist_up_mm)
        self.wrist_back = float(wrist_back_mm)
        self.grip_axis = None if grip_axis is None else _unit(_vec(grip_axis))   # None: the view's right
        self.wrist_offset = None if wrist_offset_mm is None else _vec(wrist_offset_mm)
        self.tilt = float(tilt_mm)
        self.closed = None if closed_mm is None else (float(closed_mm[0]), float(closed_mm[1]))
        self.set_view(right, up, view_dir)

    def set_view(self, right, up, view_dir=None):
        """The view's right and up vectors (and its direction, into the screen)."""
        self.right = _unit(_vec(right))
        self.up = _unit(_vec(up))
        if view_dir is not None:
            self.view_dir = _unit(_vec(view_dir))

    def move_in_view_plane(self, dx_px, dy_px, view_right_vec, view_up_vec, mm_per_px):
        """Mouse motion: dx_px to the right, dy_px up (Coin's y axis), scaled by mm_per_px."""
        self.set_view(view_right_vec, view_up_vec)
        self.centre = _add(self.centre, self.right, dx_px * mm_per_px)
        self.centre = _add(self.centre, self.up, dy_px * mm_per_px)
        return self.centre

    def wheel(self, steps, view_dir_vec, mm_per_step):
        """Wheel: `steps` > 0 pushes the hand into the screen (along the view direction)."""
        self.view_dir = _unit(_vec(view_dir_vec))
        self.centre = _add(self.centre, self.view_dir, steps * mm_per_step)
        return self.centre

    INDEX_DONE = 0.5   # with closed_mm: the index is closed half-way through the pinch,
    THUMB_FROM = 0.3   # the thumb starts closing 30% of the way

    def pinch(self, closing):
        """Key down: the grip closes at `rate_mm_s`; key up: it opens at the same rate."""
        self.closing = bool(closing)

    def tick(self, dt):
        step = self.rate * max(0.0, dt)
        if self.closing:
            self.grip = max(self.min_grip, self.grip - step)
        else:
            self.grip = min(self.max_grip, self.grip + step)
        half = 0.5 * self.grip
        axis = self.grip_axis or self.right
        index_at, thumb_at = half, -half
        if self.closed is not None:
            span = self.max_grip - self.min_grip
            c = (self.max_grip - self.grip) / span if span > 0 else 0.0   # 0 open .. 1 closed
            ci = min(1.0, c / self.INDEX_DONE)
            ct = max(0.0, (c - self.THUMB_FROM) / (1.0 - self.THUMB_FROM))
            open_half = 0.5 * self.max_grip
            index_at = open_half + (self.closed[0] - open_half) * ci
            thumb_at = -open_half + (self.closed[1] + open_half) * ct
        index = _add(_add(self.centre, axis, index_at), (0.0, 0.0, 1.0), 0.5 * self.tilt)
        thumb = _add(_add(self.centre, axis, thumb_at), (0.0, 0.0, 1.0), -0.5 * self.tilt)
        if self.wrist_offset is not None:
            wrist = _add(self.centre, self.wrist_offset)
        else:
            wrist = _add(_add(self.centre, self.up, self.wrist_up), self.view_dir, -self.wrist_back)
        return index, thumb, wrist


ARM_OPEN_MM = 100.0        # the simulated arm's hand opens about this far
ARM_CLEARANCE_MM = 15.0    # open: each fingertip this far outside the part
ARM_SQUEEZE_INDEX_MM = 15.0   # closed: the index aims this far inside the part's side
ARM_SQUEEZE_THUMB_MM = 40.0   # and the thumb this far (the core's servo bench)


def for_arm(rest, part_width_mm, right=(1.0, 0.0, 0.0), up=(0.0, 0.0, 1.0), view_dir=(0.0, 1.0, 0.0),
            rate_mm_s=60.0):
    """The mouse-and-keyboard target of the simulated arm's operator, starting at the arm's
    resting grip centre. rest: Session.arm_rest() (index, thumb, wrist, grip_axis; mm);
    part_width_mm: the part's width along the grip axis. Open, the target fingertips are
    ARM_CLEARANCE_MM outside the part (at most ARM_OPEN_MM apart); pinched, the index aims
    ARM_SQUEEZE_INDEX_MM and the thumb ARM_SQUEEZE_THUMB_MM inside the part's sides (a part
    centred on the grip centre): the operator squeezes, the arm's fingertips stop at the
    surfaces and the grasp holds.
    At rest the arm's thumb tip sits about 15 mm higher than its index tip: the target
    levels the fingertips by pitching the resting hand (fingertips and wrist together)
    about the horizontal through the grip centre across the grip axis, so the wrist target
    agrees with level fingertips (aiming the thumb lower without moving the wrist made the
    operator roll the hand off the part in our runs)."""
    import math
    index, thumb, wrist = _vec(rest["index"]), _vec(rest["thumb"]), _vec(rest["wrist"])
    axis = _unit(_vec(rest["grip_axis"]))
    centre = tuple(0.5 * (a + b) for a, b in zip(index, thumb))

    def split(p):   # along the grip axis, vertical, and the rest
        d = tuple(a - c for a, c in zip(p, centre))
        along = sum(a * b for a, b in zip(d, axis))
        return along, d[2], tuple(x - along * a - (d[2] if i == 2 else 0.0) for i, (x, a) in enumerate(zip(d, axis)))

    along, z, _side = split(index)
    pitch = math.atan2(-z, along)   # turns the index tip level with the grip centre
    w_along, w_z, w_side = split(wrist)
    na = w_along * math.cos(pitch) - w_z * math.sin(pitch)
    nz = w_along * math.sin(pitch) + w_z * math.cos(pitch)
    wrist_offset = tuple(na * a + s + (nz if i == 2 else 0.0) for i, (a, s) in enumerate(zip(axis, w_side)))
    open_mm = min(ARM_OPEN_MM, part_width_mm + 2 * ARM_CLEARANCE_MM)
    half = 0.5 * part_width_mm
    closed = (half - ARM_SQUEEZE_INDEX_MM, -(half - ARM_SQUEEZE_THUMB_MM))   # the thumb may aim past the centre
    return MouseHand(centre_mm=centre, grip_mm=open_mm, min_grip_mm=0.0, rate_mm_s=rate_mm_s,
                     right=right, up=up, view_dir=view_dir, grip_axis=axis, wrist_offset_mm=wrist_offset,
                     tilt_mm=0.0, closed_mm=closed)
