"use strict";
// Decoding of the embedded float arrays, and their conversion into display colours:
// exposure and sRGB encoding for images, colour-mapped per-pixel errors for error views.

const Pixels = (() => {
  /** Colour for pixels whose value is NaN or infinite, so they cannot pass unseen. */
  const NONFINITE = [255, 0, 255];

  /** The bytes of a base64 text; atob ignores the line breaks of the blob. */
  function decodeBase64(text) {
    const binary = atob(text);
    const bytes = new Uint8Array(binary.length);
    for (let i = 0; i < binary.length; i++) {
      bytes[i] = binary.charCodeAt(i);
    }
    return bytes;
  }

  /** IEEE-754 binary16 bit pattern to a number. */
  function halfToFloat(h) {
    const sign = h & 0x8000 ? -1 : 1;
    const exponent = (h >> 10) & 0x1f;
    const mantissa = h & 0x3ff;
    if (exponent === 0) {
      return sign * mantissa * Math.pow(2, -24);
    }
    if (exponent === 31) {
      return mantissa ? NaN : sign * Infinity;
    }
    return sign * (1 + mantissa / 1024) * Math.pow(2, exponent - 15);
  }

  /**
   * The float array in a base64 blob: little-endian f32 or f16 ("precision" in the
   * report data). DataView reads little endian whatever the machine's byte order.
   */
  function decodeFloats(text, precision) {
    const bytes = decodeBase64(text);
    const view = new DataView(bytes.buffer);
    if (precision === "f16") {
      const out = new Float32Array(bytes.length / 2);
      for (let i = 0; i < out.length; i++) {
        out[i] = halfToFloat(view.getUint16(2 * i, true));
      }
      return out;
    }
    const out = new Float32Array(bytes.length / 4);
    for (let i = 0; i < out.length; i++) {
      out[i] = view.getFloat32(4 * i, true);
    }
    return out;
  }

  /** The sRGB transfer function (IEC 61966-2-1) of a linear value in [0, 1]. */
  function srgbEncode(v) {
    return v <= 0.0031308 ? 12.92 * v : 1.055 * Math.pow(v, 1 / 2.4) - 0.055;
  }

  /** A linear value (already scaled by the exposure) as an 8-bit sRGB byte. */
  function toByte(v) {
    return Math.round(255 * srgbEncode(Math.min(Math.max(v, 0), 1)));
  }

  /** Per-pixel relative squared error, the mean over R, G, B of (a−b)²/(b²+ε). */
  function relativeSquaredError(a, b, i, epsilon) {
    let sum = 0;
    for (let c = 0; c < 3; c++) {
      const d = a[3 * i + c] - b[3 * i + c];
      sum += (d * d) / (b[3 * i + c] * b[3 * i + c] + epsilon);
    }
    return sum / 3;
  }

  function putColor(out, i, rgb) {
    out[4 * i] = rgb[0];
    out[4 * i + 1] = rgb[1];
    out[4 * i + 2] = rgb[2];
    out[4 * i + 3] = 255;
  }

  function putLut(out, i, lut, t) {
    const k = 3 * Math.round(255 * Math.min(Math.max(t, 0), 1));
    out[4 * i] = lut[k];
    out[4 * i + 1] = lut[k + 1];
    out[4 * i + 2] = lut[k + 2];
    out[4 * i + 3] = 255;
  }

  /** Writes `rgb` (linear, interleaved) × 2^stops into RGBA bytes `out`. */
  function paintImage(out, rgb, stops) {
    const gain = Math.pow(2, stops);
    const n = rgb.length / 3;
    for (let i = 0; i < n; i++) {
      const r = rgb[3 * i];
      const g = rgb[3 * i + 1];
      const b = rgb[3 * i + 2];
      if (!Number.isFinite(r + g + b)) {
        putColor(out, i, NONFINITE);
        continue;
      }
      out[4 * i] = toByte(r * gain);
      out[4 * i + 1] = toByte(g * gain);
      out[4 * i + 2] = toByte(b * gain);
      out[4 * i + 3] = 255;
    }
  }

  /**
   * Writes the relative squared error of `test` against `reference` on a log scale:
   * 10^lo and below at the bottom of the colour map, 10^hi and above at the top.
   */
  function paintRelativeError(out, test, reference, lo, hi, epsilon, lut) {
    const n = test.length / 3;
    const span = hi - lo;
    for (let i = 0; i < n; i++) {
      const e = relativeSquaredError(test, reference, i, epsilon);
      if (!Number.isFinite(e)) {
        putColor(out, i, NONFINITE);
        continue;
      }
      // log10(0) = −∞ clamps to the bottom like any tiny error.
      putLut(out, i, lut, span > 0 ? (Math.log10(e) - lo) / span : 0);
    }
  }

  /** Writes a ꟻLIP map (values in [0, 1], one per pixel) through the colour map. */
  function paintFlip(out, flip, lut) {
    for (let i = 0; i < flip.length; i++) {
      const v = flip[i];
      if (!Number.isFinite(v)) {
        putColor(out, i, NONFINITE);
        continue;
      }
      putLut(out, i, lut, v);
    }
  }

  return {
    NONFINITE,
    decodeFloats,
    halfToFloat,
    srgbEncode,
    toByte,
    relativeSquaredError,
    paintImage,
    paintRelativeError,
    paintFlip,
  };
})();
