#!/usr/bin/env python3
"""Prints the suite.toml keys of the `glider-thermal` camera path: 2 s of the
bundled glider flight (deploy/flights/glider-thermalling-ne-italy.igc) in its
tightest thermal circle (the fixes at 13:10:47-13:10:49 UTC, a 108 degree turn at 20-41 degrees of bank).

One key per 1 s fix: heading from the track to the next fix, pitch from the
climb angle, bank from the coordinated turn (tan(bank) = v * turn rate / g),
as the flight readers derive attitude for a track without one. The altitude
is the fix's GPS altitude.

  python3 deploy/bench/glider_path.py
"""
import math
import pathlib

IGC = pathlib.Path(__file__).resolve().parents[1] / "flights" / "glider-thermalling-ne-italy.igc"
START_S = 13 * 3600 + 10 * 60 + 47  # 13:10:47
KEYS = 3
EARTH_RADIUS_M = 6371000.0


def fixes():
    for line in IGC.read_text().splitlines():
        if not line.startswith("B"):
            continue
        t = int(line[1:3]) * 3600 + int(line[3:5]) * 60 + int(line[5:7])
        lat = int(line[7:9]) + int(line[9:14]) / 60000.0
        lat = -lat if line[14] == "S" else lat
        lon = int(line[15:18]) + int(line[18:23]) / 60000.0
        lon = -lon if line[23] == "W" else lon
        yield t, lat, lon, float(line[30:35])


def leg(a, b):
    """Track (deg from north), ground speed (m/s) and climb (m/s) from fix a to b."""
    dt = b[0] - a[0]
    dn = math.radians(b[1] - a[1]) * EARTH_RADIUS_M
    de = math.radians(b[2] - a[2]) * EARTH_RADIUS_M * math.cos(math.radians(a[1]))
    return math.degrees(math.atan2(de, dn)) % 360.0, math.hypot(de, dn) / dt, (b[3] - a[3]) / dt


def main():
    all_fixes = list(fixes())
    first = next(i for i, f in enumerate(all_fixes) if f[0] == START_S)
    window = all_fixes[first - 1 : first + KEYS + 1]
    for k in range(1, KEYS + 1):
        before, here, after = window[k - 1], window[k], window[k + 1]
        track_in, _, _ = leg(before, here)
        track, speed, climb = leg(here, after)
        turn = math.radians(((track - track_in + 180.0) % 360.0) - 180.0)  # rad/s over the 1 s fix
        bank = math.degrees(math.atan(speed * turn / 9.81))
        pitch = math.degrees(math.atan2(climb, speed))
        print(f"  {{ t_s = {float(k - 1):.1f}, lat_deg = {here[1]:.6f}, lon_deg = {here[2]:.6f}, alt_m = {here[3]:.1f}, "
              f"yaw_deg = {track:.1f}, pitch_deg = {pitch:.1f}, roll_deg = {bank:.1f} }},")


if __name__ == "__main__":
    main()
