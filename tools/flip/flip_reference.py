#!/usr/bin/env python3
"""Expected ꟻLIP values from NVIDIA's reference implementation, for radiant-flip's tests.

Builds deterministic image pairs, runs the official LDR- and HDR-ꟻLIP (PyPI package
`flip-evaluator`, NVlabs/flip) on them and writes tests/data/flip_expected.json with the
mean errors, selected per-pixel errors and the HDR exposure range.

Nothing derived from the images is stored: tests/common/mod.rs rebuilds the same pairs
from the recipes below (and reads the reference renders from ../shared/refs beside the repository, or $RADIANT_SHARED/refs).

Recipes (all arithmetic in float64, stored as float32; pixel (x, y) has y = 0 at the top):
  noise u(seed, x, y, c)  = (hash_u64s([seed, x, y, c]) >> 40) / 2^24, with hash_u64s
                            and mix64 exactly as radiant_math::hash (ported below).
  cornell_noise           ref = cornell-box-256-ref.pfm, test = ref * (0.7 + 0.6 u(1, x, y, c))
  cornell_blur            test = 3x3 box blur of ref, clamp-to-edge, sum over dy then dx
  cornell_exposure        test = ref * 1.5
  caustics_fireflies      ref = cornell-caustics-256-ref.pfm; where u(2, x, y, 0) < 0.01,
                          test = ref + 10 u(2, x, y, 1) on all channels, else test = ref
  gradient_quantized      200x120, s = x/199, t = y/119.
                          HDR: e = 2^(8s - 4); ref = (e (0.25 + 0.75 t), 0.5 e, e (1 - 0.75 t));
                               test = 2^(round(2 log2(ref)) / 2) per channel (half stops).
                          LDR: ref = (s, t, 1 - 0.5 (s + t)); test = round(7 ref) / 7.
  LDR inputs of the first four pairs: srgb_encode(clamp(img, 0, 1)) of both HDR images.
Extra evaluations: cornell_noise LDR at 30 pixels per degree; cornell_blur HDR with the
exposure range (-1, 2) given. Everything else uses the defaults (67 ppd, ACES).
Each evaluation stores its mean, max, probe pixels (fixed ones plus the arg-max) and the
means of an 8x8 grid of equal tiles.

Usage (from the crate root):
  pip install flip-evaluator==1.7 numpy
  python3 tools/flip_reference.py
"""
import json
import os
import pathlib
import re
import sys
from importlib import metadata

import numpy as np
import flip_evaluator as flip

REFS = pathlib.Path(os.environ.get("RADIANT_SHARED", pathlib.Path(__file__).resolve().parents[2] / ".." / "shared")) / "refs"
OUT = pathlib.Path(__file__).resolve().parents[2] / "tests" / "data" / "flip_expected.json"
MASK = (1 << 64) - 1
LOW_PPD = 30.0
FIXED_EXPOSURE = (-1.0, 2.0)


def mix64(v):
    v ^= v >> 31
    v = (v * 0x7FB5D329728EA185) & MASK
    v ^= v >> 27
    v = (v * 0x81DADEF4BC2DD44D) & MASK
    v ^= v >> 33
    return v


def hash_u64s(values):
    h = 0x9E3779B97F4A7C15
    for v in values:
        h = mix64(h ^ ((v + 0x9E3779B97F4A7C15 + ((h << 6) & MASK)) & MASK))
    return h


def noise(seed, w, h, c):
    """u(seed, x, y, c) for every pixel, as a float64 (h, w) array."""
    out = np.empty((h, w), dtype=np.float64)
    for y in range(h):
        for x in range(w):
            out[y, x] = (hash_u64s([seed, x, y, c]) >> 40) / float(1 << 24)
    return out


def read_pfm(path):
    """Reads a colour PFM into (h, w, 3) float32 with row 0 at the top."""
    with open(path, "rb") as f:
        assert f.readline().strip() == b"PF"
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        data = np.frombuffer(f.read(), dtype="<f4" if scale < 0 else ">f4")
    return np.ascontiguousarray(data.reshape(h, w, 3)[::-1]).astype(np.float32)


def srgb_encode(lin):
    c = np.clip(lin.astype(np.float64), 0.0, 1.0)
    return np.where(c <= 0.0031308, 12.92 * c, 1.055 * np.power(c, 1.0 / 2.4) - 0.055)


def f32(a):
    return np.ascontiguousarray(a, dtype=np.float32)


def box_blur(img):
    h, w, _ = img.shape
    src = img.astype(np.float64)
    acc = np.zeros_like(src)
    for dy in (-1, 0, 1):
        ys = np.clip(np.arange(h) + dy, 0, h - 1)
        for dx in (-1, 0, 1):
            xs = np.clip(np.arange(w) + dx, 0, w - 1)
            acc += src[ys][:, xs]
    return acc / 9.0


def pairs():
    """Yields (name, hdr_ref, hdr_test, ldr_ref, ldr_test), all float32 (h, w, 3)."""
    box = read_pfm(REFS / "cornell-box-256-ref.pfm")
    h, w, _ = box.shape
    n = np.stack([noise(1, w, h, c) for c in range(3)], axis=-1)
    tests = {
        "cornell_noise": box.astype(np.float64) * (0.7 + 0.6 * n),
        "cornell_blur": box_blur(box),
        "cornell_exposure": box.astype(np.float64) * 1.5,
    }
    for name, test in tests.items():
        test = f32(test)
        yield name, box, test, f32(srgb_encode(box)), f32(srgb_encode(test))

    caustics = read_pfm(REFS / "cornell-caustics-256-ref.pfm")
    h, w, _ = caustics.shape
    pick = noise(2, w, h, 0) < 0.01
    add = np.where(pick, 10.0 * noise(2, w, h, 1), 0.0)[..., None]
    test = f32(caustics.astype(np.float64) + add)
    yield "caustics_fireflies", caustics, test, f32(srgb_encode(caustics)), f32(srgb_encode(test))

    w, h = 200, 120
    s = (np.arange(w, dtype=np.float64) / (w - 1))[None, :].repeat(h, 0)
    t = (np.arange(h, dtype=np.float64) / (h - 1))[:, None].repeat(w, 1)
    e = np.exp2(8.0 * s - 4.0)
    hdr_ref = f32(np.stack([e * (0.25 + 0.75 * t), 0.5 * e, e * (1.0 - 0.75 * t)], axis=-1))
    hdr_test = f32(np.exp2(np.round(2.0 * np.log2(hdr_ref.astype(np.float64))) / 2.0))
    ldr_ref = np.stack([s, t, 1.0 - 0.5 * (s + t)], axis=-1)
    ldr_test = np.round(7.0 * ldr_ref) / 7.0
    yield "gradient_quantized", hdr_ref, hdr_test, f32(ldr_ref), f32(ldr_test)


def probe_pixels(err, w, h):
    """Fixed probe pixels plus the pixel of largest error: [[x, y, error], ...]."""
    pts = [(0, 0), (w - 1, 0), (0, h - 1), (w - 1, h - 1), (w // 2, h // 2), (w // 3, h // 4),
           (2 * w // 3, 3 * h // 4), (w // 5, 4 * h // 5)]
    y, x = np.unravel_index(int(np.argmax(err)), err.shape)
    pts.append((int(x), int(y)))
    return [[int(px), int(py), float(err[py, px])] for px, py in pts]


def block_means(err, blocks=8):
    """Means over a blocks x blocks grid of equal tiles, row-major from the top left."""
    h, w = err.shape
    tiles = err.astype(np.float64).reshape(blocks, h // blocks, blocks, w // blocks)
    return [float(v) for v in tiles.mean(axis=(1, 3)).ravel()]


def summary(err, mean):
    h, w = err.shape
    return {"mean": float(mean), "max": float(err.max()),
            "pixels": probe_pixels(err, w, h), "block_means": block_means(err)}


def compact_json(doc):
    """Indented JSON with every list of numbers on one line."""
    text = json.dumps(doc, indent=1)
    return re.sub(r"\[[-+0-9.eE,\s]*\]", lambda m: re.sub(r"\s+", " ", m.group(0))
                  .replace("[ ", "[").replace(" ]", "]"), text)


def main():
    results = []
    for name, hdr_ref, hdr_test, ldr_ref, ldr_test in pairs():
        h, w, _ = hdr_ref.shape
        ldr_map, ldr_mean, ldr_params = flip.evaluate(ldr_ref, ldr_test, "LDR", applyMagma=False)
        hdr_map, hdr_mean, hdr_params = flip.evaluate(hdr_ref, hdr_test, "HDR", applyMagma=False)
        ldr_map, hdr_map = ldr_map[..., 0], hdr_map[..., 0]
        hdr = summary(hdr_map, hdr_mean)
        hdr.update({"start_exposure": float(hdr_params["startExposure"]),
                    "stop_exposure": float(hdr_params["stopExposure"]),
                    "num_exposures": int(hdr_params["numExposures"])})
        entry = {"name": name, "width": w, "height": h,
                 "ldr": summary(ldr_map, ldr_mean), "hdr": hdr}
        if name == "cornell_noise":
            # Another viewing condition: kernel sizes scale with pixels per degree.
            m, mean, _ = flip.evaluate(ldr_ref, ldr_test, "LDR", applyMagma=False,
                                       parameters={"ppd": LOW_PPD})
            entry["ldr_low_ppd"] = summary(m[..., 0], mean)
            entry["ldr_low_ppd"]["pixels_per_degree"] = LOW_PPD
        if name == "cornell_blur":
            # A caller-given exposure range instead of the automatic one.
            params = {"startExposure": FIXED_EXPOSURE[0], "stopExposure": FIXED_EXPOSURE[1]}
            m, mean, used = flip.evaluate(hdr_ref, hdr_test, "HDR", applyMagma=False,
                                          parameters=params)
            entry["hdr_fixed_exposure"] = summary(m[..., 0], mean)
            entry["hdr_fixed_exposure"].update({
                "start_exposure": float(used["startExposure"]),
                "stop_exposure": float(used["stopExposure"]),
                "num_exposures": int(used["numExposures"])})
        results.append(entry)
        print(f"{name:20s} LDR {ldr_mean:.6f}  HDR {hdr_mean:.6f}  "
              f"exposures [{hdr_params['startExposure']:.4f}, {hdr_params['stopExposure']:.4f}]"
              f" x{hdr_params['numExposures']}")
    doc = {
        "generator": "python3 tools/flip_reference.py (from the crate root)",
        "install": "pip install flip-evaluator==1.7 numpy",
        "call": "flip_evaluator.evaluate(reference, test, 'LDR' or 'HDR', applyMagma=False)",
        "reference": f"flip-evaluator {metadata.version('flip-evaluator')} (NVlabs/flip, PyPI)",
        "numpy": np.__version__,
        "python": sys.version.split()[0],
        "pixels_per_degree": float(ldr_params["ppd"]),
        "pairs": results,
    }
    OUT.parent.mkdir(parents=True, exist_ok=True)
    OUT.write_text(compact_json(doc) + "\n")
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
