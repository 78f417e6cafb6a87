"use strict";
// Colour maps for the error views, as 33 evenly spaced knots in 8-bit sRGB, linearly
// interpolated between knots (within 3/255 of the full tables).
//
// magma and viridis are by Nathaniel J. Smith and Stéfan van der Walt (2015), released
// CC0 (public domain); the knots were sampled once from their published tables.
// magma is the colour map the ꟻLIP paper uses for its error maps (Andersson et al.,
// "FLIP: A Difference Evaluator for Alternating Images", HPG 2020); viridis, for the
// relative squared error, keeps the two kinds of error visibly apart.

const Colormaps = (() => {
  const tables = {
    magma: [
      [0, 0, 4], [3, 3, 18], [10, 8, 34], [19, 13, 52],
      [29, 17, 71], [41, 17, 90], [54, 16, 107], [68, 15, 118],
      [81, 18, 124], [93, 23, 127], [106, 28, 129], [118, 33, 129],
      [131, 38, 129], [144, 42, 129], [156, 46, 127], [170, 51, 125],
      [183, 55, 121], [196, 60, 117], [208, 65, 111], [220, 72, 105],
      [231, 82, 99], [239, 93, 94], [245, 107, 92], [249, 121, 93],
      [252, 137, 97], [253, 152, 105], [254, 167, 114], [254, 182, 124],
      [254, 196, 136], [254, 211, 149], [253, 226, 163], [252, 240, 178],
      [252, 253, 191],
    ],
    viridis: [
      [68, 1, 84], [71, 13, 96], [72, 24, 106], [72, 35, 116],
      [71, 45, 123], [69, 55, 129], [66, 64, 134], [62, 73, 137],
      [59, 82, 139], [55, 91, 141], [51, 99, 141], [47, 107, 142],
      [44, 114, 142], [41, 122, 142], [38, 130, 142], [35, 137, 142],
      [33, 145, 140], [31, 152, 139], [31, 160, 136], [34, 167, 133],
      [40, 174, 128], [50, 182, 122], [63, 188, 115], [78, 195, 107],
      [94, 201, 98], [112, 207, 87], [132, 212, 75], [152, 216, 62],
      [173, 220, 48], [194, 223, 35], [216, 226, 25], [236, 229, 27],
      [253, 231, 37],
    ],
  };

  /** The colour at t in [0, 1] (clamped; NaN maps to 0) as [r, g, b] bytes. */
  function sample(name, t) {
    const knots = tables[name];
    const n = knots.length;
    const u = Math.min(Math.max(t, 0), 1) * (n - 1) || 0;
    const i = Math.min(Math.floor(u), n - 2);
    const f = u - i;
    const a = knots[i];
    const b = knots[i + 1];
    return [
      Math.round(a[0] + f * (b[0] - a[0])),
      Math.round(a[1] + f * (b[1] - a[1])),
      Math.round(a[2] + f * (b[2] - a[2])),
    ];
  }

  /**
   * A 256-entry lookup table of the map, flattened to [r0, g0, b0, r1, ...], so
   * per-pixel colouring is one array read.
   */
  function lookupTable(name) {
    const lut = new Uint8Array(256 * 3);
    for (let i = 0; i < 256; i++) {
      lut.set(sample(name, i / 255), 3 * i);
    }
    return lut;
  }

  return { sample, lookupTable, names: Object.keys(tables) };
})();
