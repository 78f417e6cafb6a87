#!/usr/bin/env python3
"""Radiance's irradiance at the sensors of ../shared/data/cornell_irradiance_radiance.json,
averaged over many independent rtrace evaluations.

The shared file holds one Radiance run per sensor with the light sampled at fixed points
(`-dj 0`): Radiance splits a source into at most 64 partitions (MAXSPART in its
source.h), so the 130 x 105 mm light becomes 8 x 8 cells sampled at their centres
however small `-ds` is. In a penumbra that is a systematic error of several per cent,
and the indirect part of one run (-ad 8192) varies by a few per cent in shadow. This
script rebuilds the scene from the file's own specification and runs the file's rtrace
command with `-dj 1` (each partition, and the whole light at later bounces, sampled at a
random point: an unbiased estimate) on every sensor REPS times over (with `-u+` each
repetition draws new random numbers), and writes the mean and its standard error per
sensor and band. `-ad` only trades the noise of one evaluation for its cost: with 64
ambient rays per evaluation the means agree with 32 runs of the file's `-ad 8192`
(standardised differences rms 0.94), at a seventh of the cost per unit of variance.

    python3 -m venv /tmp/rad && /tmp/rad/bin/pip install pyradiance==1.3.1
    /tmp/rad/bin/python tools/radiance/cornell_sensors.py --reps 4096 --jitter 1 --ad 64 \
        --out tests/data/radiance-cornell-converged.json

pyradiance ships the Radiance 6.0a binaries; nothing of Radiance is kept in this
repository, only the averaged numbers.
"""

import argparse
import json
import math
import os
import pathlib
import subprocess
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[2]
SHARED = ROOT.parent / "shared" / "data" / "cornell_irradiance_radiance.json"


def radiance_bin():
    import pyradiance  # noqa: F401  (only for its bundled binaries)

    base = pathlib.Path(pyradiance.__file__).parent
    return base / "bin", base / "lib"


def polygon(material, name, points):
    coords = "\n".join(f"  {x!r} {y!r} {z!r}" for x, y, z in points)
    return f"{material} polygon {name}\n0\n0\n{3 * len(points)}\n{coords}\n"


def scene_rad(scene):
    """The scene block of the shared file as a Radiance description: plastic with no
    specularity (pure Lambertian), a non-reflecting `light` facing down at y = 548.7."""
    w, h, d = scene["box_mm"]
    out = []
    for name, (r, g, b) in scene["albedo_rgb"].items():
        out.append(f"void plastic {name}\n0\n0\n5 {r!r} {g!r} {b!r} 0 0\n")
    lr, lg, lb = scene["light_radiance_rgb"]
    out.append(f"void light lamp\n0\n0\n3 {lr!r} {lg!r} {lb!r}\n")
    out.append(polygon("white", "floor", [(0, 0, 0), (0, 0, d), (w, 0, d), (w, 0, 0)]))
    out.append(polygon("white", "ceiling", [(0, h, 0), (w, h, 0), (w, h, d), (0, h, d)]))
    out.append(polygon("white", "back", [(0, 0, d), (0, h, d), (w, h, d), (w, 0, d)]))
    out.append(polygon("red", "red_wall", [(w, 0, 0), (w, 0, d), (w, h, d), (w, h, 0)]))
    out.append(polygon("green", "green_wall", [(0, 0, 0), (0, h, 0), (0, h, d), (0, 0, d)]))
    (x0, x1), (z0, z1) = scene["light_rect"]["x"], scene["light_rect"]["z"]
    # Counter-clockwise seen from below: the emitting side faces -y.
    out.append(polygon("lamp", "light", [(x0, 548.7, z0), (x1, 548.7, z0), (x1, 548.7, z1), (x0, 548.7, z1)]))
    for key, top_y in (("short_block_top_xz_y165", 165.0), ("tall_block_top_xz_y330", 330.0)):
        top = scene[key]
        out.append(polygon("white", key + "_top", [(x, top_y, z) for x, z in top]))
        for k in range(4):
            (xa, za), (xb, zb) = top[k], top[(k + 1) % 4]
            out.append(polygon("white", f"{key}_side{k}", [(xa, 0, za), (xb, 0, zb), (xb, top_y, zb), (xa, top_y, za)]))
    return "".join(out)


def sensors(grid):
    """(p, n) of the sensors that have a value; rtrace gets p + 0.01 n, as the file says."""
    return [(s["p"], s["n"]) for s in grid if s["E"] is not None]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--reps", type=int, default=4096, help="evaluations per sensor")
    ap.add_argument("--jitter", type=float, default=1.0, help="rtrace -dj (the shared file used 0)")
    ap.add_argument("--ad", type=int, default=64, help="rtrace -ad (the shared file used 8192)")
    ap.add_argument("--out", type=pathlib.Path, required=True)
    ap.add_argument("--shared", type=pathlib.Path, default=SHARED)
    args = ap.parse_args()

    data = json.loads(args.shared.read_text())
    variant = data["variants"]["brief"]
    shared_cmd = variant["timing"][0]["cmd"].split()
    params = shared_cmd[1:-1]
    params[params.index("-dj") + 1] = repr(args.jitter)
    params[params.index("-ad") + 1] = str(args.ad)
    bindir, libdir = radiance_bin()
    env = dict(os.environ, RAYPATH=str(libdir))

    result = {
        "description": "Mean over independent Radiance rtrace -I evaluations of the irradiance (W/m^2, RGB) "
        "at the sensors of cornell_irradiance_radiance.json (variant brief), made by "
        "tools/radiance/cornell_sensors.py; E_stderr is the standard error of the mean.",
        "rtrace": "",
        "cmd": "rtrace " + " ".join(params) + " cornell_brief.oct",
        "evaluations_per_sensor": args.reps,
    }
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        (tmp / "cornell.rad").write_text(scene_rad(data["scene"]))
        with open(tmp / "cornell.oct", "wb") as oct_file:
            subprocess.run([bindir / "oconv", tmp / "cornell.rad"], check=True, stdout=oct_file, env=env)
        result["rtrace"] = subprocess.run([bindir / "rtrace", "-version"], check=True, capture_output=True, text=True, env=env).stdout.strip()
        for grid_name in ("floor", "back_wall"):
            points = sensors(variant[grid_name])
            rays = "".join(
                " ".join(repr(p[k] + 0.01 * n[k]) for k in range(3)) + " " + " ".join(repr(v) for v in n) + "\n"
                for p, n in points
            )
            # Each sensor `reps` times in a row; rtrace -n keeps the input order.
            rays = "".join(line for line in rays.splitlines(keepends=True) for _ in range(args.reps))
            out = subprocess.run(
                [bindir / "rtrace", *params, tmp / "cornell.oct"], input=rays, check=True, capture_output=True, text=True, env=env
            ).stdout
            values = [[float(v) for v in line.split()] for line in out.strip().splitlines()]
            assert len(values) == len(points) * args.reps, f"rtrace gave {len(values)} values for {len(points) * args.reps} rays"
            rows = []
            for i, (p, n) in enumerate(points):
                runs = values[i * args.reps : (i + 1) * args.reps]
                mean = [sum(r[b] for r in runs) / len(runs) for b in range(3)]
                var = [sum((r[b] - mean[b]) ** 2 for r in runs) / max(len(runs) - 1, 1) for b in range(3)]
                rows.append({"p": p, "n": n, "E": mean, "E_stderr": [math.sqrt(v / len(runs)) for v in var]})
            result[grid_name] = rows
    args.out.parent.mkdir(parents=True, exist_ok=True)
    # One sensor per line.
    text = json.dumps({k: v for k, v in result.items() if k not in ("floor", "back_wall")}, indent=1)[:-2]
    for grid_name in ("floor", "back_wall"):
        rows = ",\n  ".join(json.dumps(row) for row in result[grid_name])
        text += f',\n "{grid_name}": [\n  {rows}\n ]'
    args.out.write_text(text + "\n}\n")


if __name__ == "__main__":
    main()
