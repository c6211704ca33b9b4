#!/usr/bin/env python3
"""Writes the two synthetic flights bundled in deploy/flights (CSV, the format
of protocol/flight/flight.hpp). Spherical Earth for the tracks (they are
scripted, not measured); headings are the track's true azimuth at each fix.

  climb-through-layers.csv  a 15 min climb west from near Zurich, 400 m to
                            11 km MSL, through the layers of
                            deploy/scenarios/layered-climb.toml
  polar-antimeridian.csv    10 km MSL at 250 m/s: along 80N eastward across
                            the antimeridian, then over the North Pole
Usage: deploy/flights/make_synthetic.py (rewrites both files next to it)."""
import math
import os

R = 6371008.8  # mean Earth radius, m
HERE = os.path.dirname(os.path.abspath(__file__))


def to_vec(lat, lon):
    la, lo = math.radians(lat), math.radians(lon)
    return (math.cos(la) * math.cos(lo), math.cos(la) * math.sin(lo), math.sin(la))


def from_vec(v):
    x, y, z = v
    return math.degrees(math.atan2(z, math.hypot(x, y))), math.degrees(math.atan2(y, x))


def slerp(a, b, u):
    d = max(-1.0, min(1.0, sum(p * q for p, q in zip(a, b))))
    th = math.acos(d)
    if th < 1e-12:
        return a
    ka, kb = math.sin((1 - u) * th) / math.sin(th), math.sin(u * th) / math.sin(th)
    return tuple(ka * p + kb * q for p, q in zip(a, b))


def azimuth(lat1, lon1, lat2, lon2):
    p1, p2, dl = math.radians(lat1), math.radians(lat2), math.radians(lon2 - lon1)
    y = math.sin(dl) * math.cos(p2)
    x = math.cos(p1) * math.sin(p2) - math.sin(p1) * math.cos(p2) * math.cos(dl)
    return math.degrees(math.atan2(y, x)) % 360.0


def great_circle(waypoints, speed, dt):
    """Fixes every dt seconds along great-circle legs between waypoints."""
    pts = []
    t = 0.0
    for (a, b) in zip(waypoints, waypoints[1:]):
        va, vb = to_vec(*a), to_vec(*b)
        dist = math.acos(max(-1.0, min(1.0, sum(p * q for p, q in zip(va, vb))))) * R
        n = max(1, int(round(dist / (speed * dt))))
        n += 1 - n % 2  # odd: no fix at the midpoint (the pole, on the polar leg)
        for k in range(n):
            pts.append((t, from_vec(slerp(va, vb, k / n)), from_vec(slerp(va, vb, (k + 0.01) / n))))
            t += dist / n / speed
    last = to_vec(*waypoints[-1])
    prev = to_vec(*waypoints[-2])
    pts.append((t, from_vec(last), from_vec(slerp(prev, last, 1.0))))
    return pts


def write(name, header, rows):
    with open(os.path.join(HERE, name), "w") as f:
        for line in header:
            f.write("# " + line + "\n")
        f.write("time_s,lat_deg,lon_deg,alt_m,yaw_deg,pitch_deg,roll_deg\n")
        for r in rows:
            f.write("%.1f,%.6f,%.6f,%.1f,%.2f,%.2f,%.2f\n" % r)


def climb():
    rows = []
    lat0, lon0 = 47.45, 8.55
    v = 120.0  # m/s ground speed
    duration = 900
    for i in range(0, duration + 1, 5):
        t = float(i)
        alt = 400.0 + (11000.0 - 400.0) * (t / duration)
        climb_rate = (11000.0 - 400.0) / duration
        lon = lon0 - v * t / (R * math.cos(math.radians(lat0))) * 180 / math.pi
        pitch = math.degrees(math.atan2(climb_rate, v)) + 3.0  # climb angle + angle of attack
        rows.append((t, lat0, lon, alt, 270.0, pitch, 0.0))
    write("climb-through-layers.csv",
          ["Synthetic: a 15 min climb west from 47.45N 8.55E at 120 m/s, 400 m to 11000 m MSL",
           "(11.8 m/s), through stratocumulus, altostratus and cirrus (deploy/scenarios/layered-climb.toml).",
           "Written by deploy/flights/make_synthetic.py."], rows)


def polar():
    # 80N 170E -> 80N 170W (across the antimeridian on a great circle)
    # -> the pole -> 80N 10E (the meridian opposite 170W).
    # 80N 170W and 80N 10E lie on opposite meridians: the great circle through
    # them passes over the pole.
    legs = [(80.0, 170.0), (80.0, -170.0), (80.0, 10.0)]
    rows = []
    for t, (lat, lon), (lat2, lon2) in great_circle(legs, 250.0, 20.0):
        yaw = round(azimuth(lat, lon, lat2, lon2), 2) % 360.0
        rows.append((t, lat, lon, 10000.0, yaw, 0.0, 0.0))
    write("polar-antimeridian.csv",
          ["Synthetic: 10 km MSL at 250 m/s, fixes every 20 s: along a great circle from 80N 170E",
           "across the antimeridian to 80N 170W, then north over the pole (the nearest fixes",
           "are 2.5 km either side of it) and south along 10E to 80N. Headings are the track azimuth at each fix.",
           "Written by deploy/flights/make_synthetic.py."], rows)


if __name__ == "__main__":
    climb()
    polar()
