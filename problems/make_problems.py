#!/usr/bin/env python3
"""Write the toolpaths (APT CL files) of the bundled example problems.

Run from the repository root (Python 3, standard library only):

    python3 problems/make_problems.py

It overwrites these two files and always writes exactly the same bytes:

* problems/seed_head_head/impeller_blade.cls -- 5-axis (MULTAX/ON) flank finishing pass
  along one blade of a centrifugal impeller, for the seed's double swivel head
  (problems/seed_head_head/machine.json).

  The blade is a twisted ruled surface: for t in [0, 1] the tool tip runs along the blade's
  hub curve P(t) (radius 35 -> 100 mm, wrapping about 36 degrees about the impeller axis z
  while dropping from z = 50 to z = 8 mm, 89 mm long) and the tool axis is the ruling
  O(t) of the blade, so the tool's flank cuts the blade. O(t) tilts from 12 to 38 degrees off
  the vertical and swings about 61 degrees about z (C axis), never closer than 12 degrees to
  the singular vertical pose of the head. Points are spaced evenly, 0.15 mm, along the tip.
  The pass is entered along a 12 mm straight lead-in (points every 1 mm, tool axis fixed)
  that meets the blade at 35 degrees, sideways (a sharp corner: an exact stop), and left by
  a 25 mm RAPID retract along the tool axis (another exact stop).

* problems/xyz_pocket/pocket_contour.cls -- 3-axis (MULTAX/OFF) pocket finishing pass for a
  3-axis vertical mill (problems/xyz_pocket/machine.json), in tool-centre CL points of a
  10 mm end mill:
  a helical ramp (radius 5 mm, centre (-25, 0), descending from z = +1 to the floor at
  z = -6 over 3.5 turns, the last half turn easing smoothly to level, then half a turn flat
  at the floor), a 10 mm straight lead-in to the wall
  (sharp corners at both ends), one climb-milling (counter-clockwise) lap of the rounded
  rectangle 80 x 50 mm with 6 mm corner radii (the contour is centred on the origin) with a
  5 mm overlap, a 5 mm straight lead-out off the wall, and a RAPID retract to z = +5.
  Arcs are sampled densely (0.2 mm chords), straight lines every 0.5 mm.

Units: mm; feeds in FEDRAT/MMPM are mm/min as APT defines.
"""

import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))

# Point spacing along the tool tip, mm.
BLADE_STEP = 0.15  # blade pass (even in arc length)
LEAD_STEP = 1.0  # blade lead-in line
HELIX_STEP = 0.3  # pocket ramp helix
ARC_STEP = 0.2  # pocket corner arcs
LINE_STEP = 0.5  # pocket straight lines


# --------------------------------------------------------------------------------------------
# Small vector helpers (no numpy).

def add(a, b):
    return tuple(x + y for x, y in zip(a, b))


def sub(a, b):
    return tuple(x - y for x, y in zip(a, b))


def scale(a, s):
    return tuple(x * s for x in a)


def norm(a):
    return math.sqrt(sum(x * x for x in a))


def unit(a):
    n = norm(a)
    return tuple(x / n for x in a)


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def angle_deg(a, b):
    c = dot(a, b) / (norm(a) * norm(b))
    return math.degrees(math.acos(max(-1.0, min(1.0, c))))


def resample_even(curve, t0, t1, spacing, samples=200000):
    """Parameters t of points spaced `spacing` apart (as evenly as the length allows) along
    curve(t), t in [t0, t1], by inverting a dense cumulative chord-length table."""
    ts = [t0 + (t1 - t0) * i / samples for i in range(samples + 1)]
    pts = [curve(t) for t in ts]
    s = [0.0]
    for i in range(1, len(pts)):
        s.append(s[-1] + norm(sub(pts[i], pts[i - 1])))
    length = s[-1]
    n = max(1, round(length / spacing))
    out = []
    j = 0
    for k in range(n + 1):
        target = length * k / n
        while j < samples - 1 and s[j + 1] < target:
            j += 1
        f = (target - s[j]) / (s[j + 1] - s[j])
        out.append(ts[j] + f * (ts[j + 1] - ts[j]))
    out[0], out[-1] = t0, t1
    return out, length


# --------------------------------------------------------------------------------------------
# Problem 1: impeller blade, 5 axes.

def smoothstep(t):
    return t * t * (3.0 - 2.0 * t)


def blade_tip(t):
    """Hub curve of the blade: the tool tip (mm)."""
    r = 35.0 + 65.0 * t
    phi = math.radians(-20.0 + 55.0 * (t - 0.35 * t * t))
    z = 8.0 + 42.0 * (1.0 - t) ** 2
    return (r * math.cos(phi), r * math.sin(phi), z)


def blade_axis(t):
    """Ruling of the blade: the unit tool axis, tip -> spindle."""
    phi = math.radians(-20.0 + 55.0 * (t - 0.35 * t * t))
    tilt = math.radians(12.0 + 26.0 * smoothstep(t))
    psi = phi + math.radians(-100.0 + 25.0 * t)
    return (math.sin(tilt) * math.cos(psi), math.sin(tilt) * math.sin(psi), math.cos(tilt))


def impeller_blade():
    ts, length = resample_even(blade_tip, 0.0, 1.0, BLADE_STEP)
    blade = [(blade_tip(t), blade_axis(t)) for t in ts]

    # Lead-in: a straight line into the blade's start at the start orientation, turned
    # 35 degrees away from the blade's start tangent, sideways (perpendicular to the tool axis).
    p0, o0 = blade[0]
    tan0 = unit(sub(blade[1][0], p0))
    side = unit(cross(o0, tan0))
    a = math.radians(35.0)
    lead_dir = unit(add(scale(tan0, math.cos(a)), scale(side, math.sin(a))))
    lead_start = sub(p0, scale(lead_dir, 12.0))

    # Retract: 25 mm along the final tool axis.
    p1, o1 = blade[-1]
    retract = add(p1, scale(o1, 25.0))

    tilts = [math.degrees(math.acos(o[2])) for _, o in blade]
    cs = [math.degrees(math.atan2(o[0], -o[1])) for _, o in blade]
    corner = angle_deg(sub(p0, lead_start), tan0)

    lines = [
        "TOOL PATH/BLADE_FLANK_FINISH,TOOL,TBM_D6_R3",
        "TLDATA/MILL,6.0000,3.0000,50.0000,2.0000,0.0000",
        "MSYS/0.0000,0.0000,0.0000,1.0000000,0.0000000,0.0000000,0.0000000,1.0000000,0.0000000",
        "$$ feedopt example: flank finishing of one impeller blade (twisted ruled surface)",
        "$$ generated by problems/make_problems.py -- units mm",
        "$$ tool tip on the hub curve, tool axis along the blade ruling; tilt %.1f..%.1f deg"
        % (min(tilts), max(tilts)),
        "LOADTL/1",
        "SPINDL/RPM,14000.0000,CLW",
        "COOLNT/MIST",
        "MULTAX/ON",
        "FEDRAT/MMPM,6000.0000",
    ]

    def goto5(p, o):
        return "GOTO/%.6f,%.6f,%.6f,%.9f,%.9f,%.9f" % (p + o)

    lines.append("$$ lead-in, %.1f deg into the blade start" % corner)
    n_lead = round(12.0 / LEAD_STEP)
    for k in range(n_lead):
        lines.append(goto5(add(lead_start, scale(lead_dir, 12.0 * k / n_lead)), o0))
    lines.append("$$ blade pass, %.3f mm" % length)
    for p, o in blade:
        lines.append(goto5(p, o))
    lines.append("$$ retract along the tool axis")
    lines.append("RAPID")
    lines.append(goto5(retract, o1))
    lines.append("COOLNT/OFF")
    lines.append("END-OF-PATH")

    info = ("impeller_blade.cls: %d GOTO, blade %.1f mm, tilt %.1f..%.1f deg, C %.1f..%.1f deg, "
            "lead-in corner %.1f deg" % (len(blade) + n_lead + 1, length, min(tilts), max(tilts),
                                         min(cs), max(cs), corner))
    return lines, info


# --------------------------------------------------------------------------------------------
# Problem 2: 2.5D pocket, 3 axes.

def pocket_contour():
    pts = []

    def push(p):
        if not pts or norm(sub(p, pts[-1])) > 1e-9:
            pts.append(p)

    def line(a, b, step):
        n = max(1, math.ceil(norm(sub(b, a)) / step - 1e-9))
        for k in range(1, n + 1):
            push(add(a, scale(sub(b, a), k / n)))

    def arc(c, r, a0, a1, z, step):
        """Counter-clockwise arc about c from angle a0 to a1 (radians) at height z."""
        n = max(1, math.ceil(r * (a1 - a0) / step - 1e-9))
        for k in range(1, n + 1):
            a = a0 + (a1 - a0) * k / n
            push((c[0] + r * math.cos(a), c[1] + r * math.sin(a), z))

    # Helical ramp: centre (-25, 0), radius 5, counter-clockwise from angle 180 deg.
    hc, hr = (-25.0, 0.0), 5.0
    z_top, z_floor = 1.0, -6.0
    turns_ramp, turns_blend = 3.0, 0.5
    # z descends at a constant pitch, then its slope eases to zero over half a turn
    # (a cubic blend, so the ramp runs smoothly into the flat circle at the floor).
    th_r = 2 * math.pi * turns_ramp
    th_b = 2 * math.pi * turns_blend
    # depth(theta): slope k on [0, th_r], then k*(1 - smoothstep) over the blend.
    # Integral of the blend slope is k*th_b/2, so k*(th_r + th_b/2) = z_top - z_floor.
    k = (z_top - z_floor) / (th_r + th_b / 2.0)

    def depth(th):
        if th <= th_r:
            return k * th
        x = min(1.0, (th - th_r) / th_b)
        # integral of (1 - 3x^2 + 2x^3) dx = x - x^3 + x^4/2
        return k * th_r + k * th_b * (x - x ** 3 + 0.5 * x ** 4)

    def helix(th):
        a = math.pi + th
        return (hc[0] + hr * math.cos(a), hc[1] + hr * math.sin(a), z_top - depth(th))

    # Ramp and blend, then flat at the floor until a whole number of turns (4), so the helix
    # ends at angle 180 deg again, at (-30, 0, -6).
    th_end = th_r + th_b + 2 * math.pi * 0.5
    th_end = 2 * math.pi * math.ceil(th_end / (2 * math.pi))
    n = math.ceil(th_end * hr / HELIX_STEP)
    for i in range(n + 1):
        push(helix(th_end * i / n))
    ramp_end = pts[-1]  # (-30, 0, -6), moving in -y

    # Lead-in to the wall: straight, -x, 10 mm (turns 90 deg at each end).
    wall_start = (-40.0, 0.0, z_floor)
    line(ramp_end, wall_start, LINE_STEP)

    # Rounded rectangle 80 x 50, corner radius 6, counter-clockwise (climb), from (-40, 0)
    # going -y, one full lap plus 5 mm overlap.
    w, h, r = 40.0, 25.0, 6.0
    z = z_floor
    line(wall_start, (-w, -h + r, z), LINE_STEP)
    arc((-w + r, -h + r), r, math.pi, 1.5 * math.pi, z, ARC_STEP)
    line((-w + r, -h, z), (w - r, -h, z), LINE_STEP)
    arc((w - r, -h + r), r, 1.5 * math.pi, 2.0 * math.pi, z, ARC_STEP)
    line((w, -h + r, z), (w, h - r, z), LINE_STEP)
    arc((w - r, h - r), r, 0.0, 0.5 * math.pi, z, ARC_STEP)
    line((w - r, h, z), (-w + r, h, z), LINE_STEP)
    arc((-w + r, h - r), r, 0.5 * math.pi, math.pi, z, ARC_STEP)
    line((-w, h - r, z), wall_start, LINE_STEP)
    overlap_end = (-w, -5.0, z)
    line(wall_start, overlap_end, LINE_STEP)
    # Lead-out off the wall: 5 mm in +x (a 90 deg corner).
    lead_out = (-w + 5.0, -5.0, z)
    line(overlap_end, lead_out, LINE_STEP)
    n_feed = len(pts)
    retract = (lead_out[0], lead_out[1], 5.0)

    lines = [
        "TOOL PATH/POCKET_FINISH,TOOL,EM_D10",
        "TLDATA/MILL,10.0000,0.0000,40.0000,0.0000,0.0000",
        "MSYS/0.0000,0.0000,0.0000,1.0000000,0.0000000,0.0000000,0.0000000,1.0000000,0.0000000",
        "$$ feedopt example: 2.5D pocket finishing, helical ramp-in then one contour lap",
        "$$ generated by problems/make_problems.py -- units mm, tool-centre CL points",
        "LOADTL/2",
        "SPINDL/RPM,10000.0000,CLW",
        "COOLNT/FLOOD",
        "MULTAX/OFF",
        "FEDRAT/MMPM,9000.0000",
    ]
    for p in pts:
        lines.append("GOTO/%.6f,%.6f,%.6f" % p)
    lines.append("$$ retract")
    lines.append("RAPID")
    lines.append("GOTO/%.6f,%.6f,%.6f" % retract)
    lines.append("COOLNT/OFF")
    lines.append("END-OF-PATH")

    length = sum(norm(sub(pts[i], pts[i - 1])) for i in range(1, len(pts)))
    info = "pocket_contour.cls: %d GOTO, %.1f mm at feed" % (n_feed + 1, length)
    return lines, info


def material_pocket():
    """A 40 x 20 x 3 mm pocket in a 60 x 40 x 10 mm block (problems/material_pocket): plunge,
    four raster passes (a full-width slot, then side steps of 3.67 mm, a_e < D/2) leaving
    0.5 mm on the walls, then one finishing lap that takes the 0.5 mm off."""
    d, r = 8.0, 4.0
    z_cut = -3.0
    x0, x1, y0, y1 = 14.0, 46.0, 14.0, 26.0  # tool-centre rectangle of the finished pocket
    leave = 0.5
    rx0, rx1, ry0, ry1 = x0 + leave, x1 - leave, y0 + leave, y1 - leave
    passes = 4
    lines = [
        "TOOL PATH/POCKET_ROUGH_FINISH,TOOL,EM_D8",
        "$$ feedopt example: a pocket roughed by a slot and side steps, then finished",
        "$$ generated by problems/make_problems.py -- units mm, tool-tip CL points",
        "CUTTER/%.4f,%.4f" % (d, 0.0),
        "LOADTL/1",
        "SPINDL/RPM,10000.0000,CLW",
        "MULTAX/OFF",
        "GOTO/%.6f,%.6f,%.6f" % (rx0, ry0, 10.0),
        "RAPID",
        "GOTO/%.6f,%.6f,%.6f" % (rx0, ry0, 2.0),
        "FEDRAT/MMPM,300.0000",
        "GOTO/%.6f,%.6f,%.6f" % (rx0, ry0, z_cut),
        "FEDRAT/MMPM,1200.0000",
    ]
    pts = [(rx0, ry0, z_cut)]
    for k in range(passes):
        y = ry0 + (ry1 - ry0) * k / (passes - 1)
        xa, xb = (rx0, rx1) if k % 2 == 0 else (rx1, rx0)
        if k > 0:
            pts.append((xa, y, z_cut))
        pts.append((xb, y, z_cut))
    # Finishing lap, climb milling (tool on the wall's left: clockwise seen from above).
    lap = [(x0, y1), (x0, y0), (x1, y0), (x1, y1), (x0, y1)]
    pts.extend((x, y, z_cut) for x, y in lap)
    for p in pts[1:]:
        lines.append("GOTO/%.6f,%.6f,%.6f" % p)
    lines.append("RAPID")
    lines.append("GOTO/%.6f,%.6f,%.6f" % (x0, y1, 10.0))
    lines.append("END-OF-PATH")
    area = (x1 - x0) * (y1 - y0) + 2 * r * ((x1 - x0) + (y1 - y0)) + math.pi * r * r
    info = "pocket.cls: pocket volume %.3f mm^3 (area %.3f mm^2 x %.1f mm)" % (
        area * -z_cut, area, -z_cut)
    return lines, info


def write(rel, lines):
    path = os.path.join(HERE, rel)
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w", newline="\n") as f:
        f.write("\n".join(lines) + "\n")


def main():
    lines, info = impeller_blade()
    write(os.path.join("seed_head_head", "impeller_blade.cls"), lines)
    print(info)
    lines, info = pocket_contour()
    write(os.path.join("xyz_pocket", "pocket_contour.cls"), lines)
    print(info)
    lines, info = material_pocket()
    write(os.path.join("material_pocket", "pocket.cls"), lines)
    print(info)


if __name__ == "__main__":
    main()
