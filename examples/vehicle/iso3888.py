"""iso3888 — the ISO 3888-1:2018 double lane change (severe lane change) track: cone
layout, the reference path the driver follows, and the check that a car stays inside.

Layout (ISO 3888-1, Table 1; b = vehicle width): section 1 length 15 m, lane width
1.1 b + 0.25; section 2 length 30 m (lane change); section 3 length 25 m, width
1.2 b + 0.25, lateral offset 3.5 m; section 4 length 25 m; section 5 length 15 m,
width 1.3 b + 0.25; section 6 (exit) length 15 m, width 1.3 b + 0.25. The lane change
is to the left (ISO 8855 y). Offsets are between the right-hand cone rows: lanes 1
and 5/6 share their right-hand row (y = -w1/2), lane 3's right-hand row is 3.5 m to
the left of it (this reading of the figure is the one of the standard's drawing,
where the 3.5 m dimension runs between the right-hand cones of lanes 1 and 3).

Must never: depend on the simulation (pure geometry; vehicle.py's driver and
run.py's check both import it, so the path and the cones cannot drift apart).
"""

import math

SECTIONS = (15.0, 30.0, 25.0, 25.0, 15.0, 15.0)
OFFSET = 3.5


def lanes(b):
    """[(x_start, x_end, y_right, y_left)] of the three gated lanes for a car of width b."""
    w1, w3, w5 = 1.1 * b + 0.25, 1.2 * b + 0.25, 1.3 * b + 0.25
    x = [0.0]
    for s in SECTIONS:
        x.append(x[-1] + s)
    right = -w1 / 2
    return [
        (x[0], x[1], right, right + w1),
        (x[2], x[3], right + OFFSET, right + OFFSET + w3),
        (x[4], x[6], right, right + w5),
    ]


def _blend(s):
    """Smooth step 0 -> 1 on s in [0, 1] with zero slope and curvature at both ends
    (quintic 10 s^3 - 15 s^4 + 6 s^5)."""
    s = min(1.0, max(0.0, s))
    return s * s * s * (10.0 - 15.0 * s + 6.0 * s * s)


def reference_y(x, b):
    """Lateral position (m) of the driver's reference path at longitudinal position x:
    the centre of each lane, joined by quintic steps across sections 2 and 4."""
    (a0, a1, r1, l1), (c0, c1, r3, l3), (e0, e1, r5, l5) = lanes(b)
    y1, y3, y5 = (r1 + l1) / 2, (r3 + l3) / 2, (r5 + l5) / 2
    if x < a1:
        return y1
    if x < c0:
        return y1 + (y3 - y1) * _blend((x - a1) / (c0 - a1))
    if x < c1:
        return y3
    if x < e0:
        return y3 + (y5 - y3) * _blend((x - c1) / (e0 - c1))
    return y5


def violations(xs, ys, psis, b, lf, lr):
    """Worst cone intrusion (m, > 0 = outside) of the car's footprint: the four
    corners of the rectangle of width b between the front and rear axles, at every
    sample (x, y, yaw) whose corners lie inside a gated lane's length. Returns
    (worst_margin, x_at_worst): worst_margin < 0 means inside by that much."""
    worst, where = -math.inf, None
    gates = lanes(b)
    for x, y, psi in zip(xs, ys, psis):
        c, s = math.cos(psi), math.sin(psi)
        for dx in (lf, -lr):
            for dy in (b / 2, -b / 2):
                cx, cy = x + c * dx - s * dy, y + s * dx + c * dy
                for x0, x1, yr, yl in gates:
                    if x0 <= cx <= x1:
                        m = max(yr - cy, cy - yl)
                        if m > worst:
                            worst, where = m, cx
    return worst, where
