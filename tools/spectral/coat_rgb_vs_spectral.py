#!/usr/bin/env python3
"""RGB versus spectral transport inside a coated diffuse layer, for one saturated RGB
reflectance: why an RGB renderer and a spectral one (pbrt-v4) disagree on a surface
like bitterli/coffee's orange plastic although both reproduce the colour of one bounce.

The reflectance is upsampled to a smooth spectrum as pbrt-v4 does, by a sigmoid of a
quadratic in wavelength (Jakob & Hanika 2019, "A Low-Dimensional Function Space for
Efficient Spectral Upsampling"), fitted here so that its linear-sRGB projection under
D65 equals the RGB value. Light entering a smooth coat (eta 1.5) bounces between the
base and the coat's underside (diffuse internal reflectance r_i); the base reflectance
enters once per bounce, so what leaves is nonlinear in it and the spectral result's
projection differs from the RGB product. Prints the ratio spectral / RGB per channel.

    python3 -m venv v && v/bin/pip install numpy scipy colour-science
    v/bin/python coat_rgb_vs_spectral.py 1 0.378676 0.013473
"""
import sys
import warnings

import numpy as np
import scipy.optimize as so

warnings.filterwarnings("ignore")
import colour  # noqa: E402

SHAPE = colour.SpectralShape(360, 830, 1)
LAM = np.arange(360, 831, 1.0)
CMFS = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(SHAPE).values
D65 = colour.SDS_ILLUMINANTS["D65"].copy().align(SHAPE).values
XYZ_TO_SRGB = np.array(
    [
        [3.2404542, -1.5371385, -0.4985314],
        [-0.9692660, 1.8760108, 0.0415560],
        [0.0556434, -0.2040259, 1.0572252],
    ]
)
NORM = 1.0 / np.sum(D65 * CMFS[:, 1])
X = (LAM - 360.0) / (830.0 - 360.0)


def to_rgb(reflectance):
    return XYZ_TO_SRGB @ (NORM * np.sum((reflectance * D65)[:, None] * CMFS, axis=0))


def sigmoid(z):
    return 0.5 + z / (2.0 * np.sqrt(1.0 + z * z))


def upsample(rgb):
    best = None
    for start in [(0, 0, 0), (-50, 60, -10), (-100, 150, -40), (50, -10, -5), (-20, 40, -15)]:
        fit = so.least_squares(
            lambda c: to_rgb(sigmoid(c[0] * X * X + c[1] * X + c[2])) - rgb,
            start,
            method="lm",
            max_nfev=20000,
        )
        if best is None or fit.cost < best.cost:
            best = fit
    c = best.x
    return sigmoid(c[0] * X * X + c[1] * X + c[2])


def main():
    rgb = np.array([float(v) for v in sys.argv[1:4]]) if len(sys.argv) > 3 else np.array(
        [1.0, 0.378676, 0.013473]
    )
    spectrum = upsample(rgb)
    print("upsampled spectrum projects to", np.round(to_rgb(spectrum), 6))
    # Smooth coat, eta 1.5: normal-incidence Fresnel 0.04; diffuse internal reflectance
    # 1 - (1 - 0.092) / eta^2 = 0.596 (0.092: the outside's hemispherical Fresnel).
    f0, r_i = 0.04, 0.596
    for bounces in (4, 100):
        def leaving(r):
            return (1 - f0) * r * (1 - r_i) * sum((r * r_i) ** j for j in range(bounces + 1))
        spectral = to_rgb(leaving(spectrum))
        plain = leaving(rgb)
        print(
            f"{bounces:3d} internal bounces: spectral {np.round(spectral, 4)}"
            f"  RGB {np.round(plain, 4)}  ratio {np.round(spectral / plain, 3)}"
        )


if __name__ == "__main__":
    main()
