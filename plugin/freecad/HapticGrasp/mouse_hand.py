"""A simulated hand driven by the mouse and keyboard (pure Python, no FreeCAD import).

State: the hand centre (mm, document coordinates) and the grip opening (mm, distance
between the index and thumb fingertips). The GUI feeds it from Coin events on the 3D view:
mouse motion moves the centre in the view plane, the wheel moves it along the view
direction (depth), a key held pinches (closes the grip at `rate_mm_s`), releasing the key
opens it again. tick(dt) advances the grip and returns (index_mm, thumb_mm, wrist_mm):
index and thumb on either side of the centre along the view's right vector, the wrist
`wrist_up_mm` above the centre along the view's up vector and `wrist_back_mm` behind it
(towards the viewer).
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
                 wrist_up_mm=100.0, wrist_back_mm=0.0):
        self.centre = _vec(centre_mm)
        self.grip = float(grip_mm)
        self.min_grip = float(min_grip_mm)
        self.max_grip = float(grip_mm if max_grip_mm is None else max_grip_mm)
        self.rate = float(rate_mm_s)
        self.closing = False
        self.wrist_up = float(wrist_up_mm)
        self.wrist_back = float(wrist_back_mm)
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
        index = _add(self.centre, self.right, half)
        thumb = _add(self.centre, self.right, -half)
        wrist = _add(_add(self.centre, self.up, self.wrist_up), self.view_dir, -self.wrist_back)
        return index, thumb, wrist
