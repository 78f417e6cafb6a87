"use strict";
// Self-test, run only when the page is opened with #selftest (e.g. by a headless
// browser with --dump-dom). It drives the controls the way a person would — through
// their input events — reads the displayed pixels back from the canvases, and writes a
// JSON result into a <pre> element with id "selftest-result" for the test harness.
//
// The expected colours here are computed from the decoded data; the harness repeats
// the check against the values it wrote into the report, so both sides must agree.

(() => {
  if (!SelftestHooks.active) return;

  /** RGBA bytes of canvas pixel (x, y). */
  function readPixel(canvas, x, y) {
    const ctx = canvas.getContext("2d");
    return Array.from(ctx.getImageData(x, y, 1, 1).data);
  }

  /** The canvas pixel showing the centre of image pixel (px, py). */
  function canvasPixelOf(canvas, px, py) {
    const p = Viewer.imageToCanvas(canvas, px + 0.5, py + 0.5);
    return { x: Math.floor(p.x), y: Math.floor(p.y) };
  }

  function setControl(id, value, eventName) {
    const element = document.getElementById(id);
    element.value = String(value);
    element.dispatchEvent(new Event(eventName, { bubbles: true }));
    Viewer.renderNow();
  }

  /** Expected sRGB bytes of linear pixel p of image img at `stops` exposure. */
  function expectedBytes(img, p, stops) {
    const gain = Math.pow(2, stops);
    return [0, 1, 2].map((c) => Pixels.toByte(img.rgb[3 * p + c] * gain));
  }

  /** Within one step of 8-bit rounding, per channel. */
  function close(rgba, rgb) {
    return rgb.every((v, c) => Math.abs(rgba[c] - v) <= 1);
  }

  function readTable() {
    const keys = Array.from(document.querySelectorAll("#metrics thead th[data-key]")).map((th) => th.dataset.key);
    const rows = Array.from(document.querySelectorAll("#metrics tbody tr")).map((tr) => {
      const cells = {};
      for (const td of tr.querySelectorAll("td")) {
        const raw = td.dataset.value;
        cells[td.dataset.key] = { text: td.textContent, value: raw === "null" ? null : Number(raw) };
      }
      return { method: tr.dataset.method, cells };
    });
    return { keys, rows };
  }

  /** Any src/href that would reach outside the file (the report must have none). */
  function externalReferences() {
    return Array.from(document.querySelectorAll("[src], [href]"))
      .map((e) => e.getAttribute("src") || e.getAttribute("href"))
      .filter((url) => !url.startsWith("#") && !url.startsWith("data:"));
  }

  const result = { finished: false, settled: false, checks: {}, errors: SelftestHooks.errors };
  try {
    const images = Viewer.images;
    const ref = images[0];
    const px = Math.floor(ref.width / 2);
    const py = Math.floor(ref.height / 2);
    const p = py * ref.width + px;
    result.pixel = [px, py];
    result.linear = images.map((img) => (img.rgb ? Array.from(img.rgb.slice(3 * p, 3 * p + 3)) : null));
    // Magnify around the test pixel first, so that with any image size each image
    // pixel covers whole canvas pixels (no filtering mixes in its neighbours).
    Viewer.state.view = { cx: px + 0.5, cy: py + 0.5, span: Math.min(ref.width, 16) };

    // Swipe: A = reference, B = the first method; the split at the right edge shows
    // only A, at the left edge only B.
    const b = Math.min(1, images.length - 1);
    setControl("swipe-a", 0, "change");
    setControl("swipe-b", b, "change");
    const swipe = Viewer.swipeCanvas;
    const at = canvasPixelOf(swipe, px, py);
    setControl("swipe-position", 1000, "input");
    const swipeBefore = readPixel(swipe, at.x, at.y);
    setControl("swipe-position", 0, "input");
    const swipeAfter = readPixel(swipe, at.x, at.y);
    result.checks.swipe = {
      canvasPixel: [at.x, at.y],
      before: swipeBefore,
      after: swipeAfter,
      expectedBefore: expectedBytes(ref, p, 0),
      expectedAfter: expectedBytes(images[b], p, 0),
      changed: swipeBefore.some((v, c) => v !== swipeAfter[c]),
    };
    result.checks.swipe.ok =
      result.checks.swipe.changed &&
      close(swipeBefore, result.checks.swipe.expectedBefore) &&
      close(swipeAfter, result.checks.swipe.expectedAfter);
    setControl("swipe-position", 500, "input");

    // Exposure: the reference panel at 0 EV and at +1 EV.
    const panel = Viewer.panels[0].canvas;
    const pp = canvasPixelOf(panel, px, py);
    setControl("exposure", 0, "input");
    const exposureBefore = readPixel(panel, pp.x, pp.y);
    setControl("exposure", 1, "input");
    const exposureAfter = readPixel(panel, pp.x, pp.y);
    result.checks.exposure = {
      stops: 1,
      before: exposureBefore,
      after: exposureAfter,
      expectedBefore: expectedBytes(ref, p, 0),
      expectedAfter: expectedBytes(ref, p, 1),
      changed: exposureBefore.some((v, c) => v !== exposureAfter[c]),
      label: document.getElementById("exposure-value").textContent,
    };
    result.checks.exposure.ok =
      result.checks.exposure.changed &&
      close(exposureBefore, result.checks.exposure.expectedBefore) &&
      close(exposureAfter, result.checks.exposure.expectedAfter);
    setControl("exposure", 0, "input");

    // Error views of the first method's panel at the same pixel.
    if (images.length > 1) {
      const methodPanel = Viewer.panels[1].canvas;
      const mp = canvasPixelOf(methodPanel, px, py);
      setControl("display-mode", "relerr", "change");
      const relerr = Pixels.relativeSquaredError(images[1].rgb, ref.rgb, p, Viewer.data.relmseEpsilon);
      result.checks.relerr = { value: relerr, color: readPixel(methodPanel, mp.x, mp.y) };
      setControl("display-mode", "flip", "change");
      result.checks.flip = {
        value: images[1].flip ? images[1].flip[p] : null,
        color: readPixel(methodPanel, mp.x, mp.y),
      };
      setControl("display-mode", "image", "change");
    }

    // Readout: hover the reference panel over the test pixel.
    const rect = panel.getBoundingClientRect();
    const hover = Viewer.imageToCanvas(panel, px + 0.5, py + 0.5);
    panel.dispatchEvent(
      new PointerEvent("pointermove", {
        bubbles: true,
        clientX: rect.left + (hover.x * rect.width) / panel.width,
        clientY: rect.top + (hover.y * rect.height) / panel.height,
      }),
    );
    Viewer.renderNow();
    result.checks.readout = {
      position: document.getElementById("hover-position").textContent,
      text: Viewer.panels[0].readout.textContent,
    };

    // Zoom: one wheel step in, about the panel centre, narrows the view.
    const spanBefore = Viewer.state.view.span;
    panel.dispatchEvent(
      new WheelEvent("wheel", {
        bubbles: true,
        cancelable: true,
        deltaY: -100,
        clientX: rect.left + rect.width / 2,
        clientY: rect.top + rect.height / 2,
      }),
    );
    result.checks.zoom = { spanBefore, spanAfter: Viewer.state.view.span };

    // Pan: drag the reference panel 20 CSS pixels to the right; the view centre moves
    // left by that distance in image pixels.
    const cxBefore = Viewer.state.view.cx;
    const scale = panel.width / Viewer.state.view.span;
    const dragAt = { clientX: rect.left + rect.width / 2, clientY: rect.top + rect.height / 2 };
    const pointer = (type, dx) =>
      panel.dispatchEvent(
        new PointerEvent(type, { bubbles: true, pointerId: 1, clientX: dragAt.clientX + dx, clientY: dragAt.clientY }),
      );
    pointer("pointerdown", 0);
    pointer("pointermove", 20);
    pointer("pointerup", 20);
    result.checks.pan = {
      moved: cxBefore - Viewer.state.view.cx,
      expected: (20 * panel.width) / rect.width / scale,
    };

    // Synchronized views: after zooming and panning, the test pixel shows the same
    // image's value wherever it now lies, in panels and swipe canvas alike.
    Viewer.state.hover = null;
    setControl("swipe-position", 1000, "input");
    const shownAt = (canvas) => {
      const q = canvasPixelOf(canvas, px, py);
      return readPixel(canvas, q.x, q.y);
    };
    result.checks.sync = {
      reference: shownAt(panel),
      swipe: shownAt(Viewer.swipeCanvas),
      method: images.length > 1 ? shownAt(Viewer.panels[1].canvas) : null,
    };

    // Nearest neighbour when magnified: 8 image pixels across the panel, and points near
    // the left and right edges inside the test pixel both show its exact colour.
    Viewer.state.view = { cx: px + 0.5, cy: py + 0.5, span: 8 };
    Viewer.renderNow();
    const inside = (fx) => {
      const q = Viewer.imageToCanvas(panel, px + fx, py + 0.5);
      return readPixel(panel, Math.floor(q.x), Math.floor(q.y));
    };
    result.checks.nearest = { left: inside(0.1), right: inside(0.9), expected: expectedBytes(ref, p, 0) };
    Viewer.state.view = Viewer.fitView();
    setControl("swipe-position", 500, "input");

    result.table = readTable();
    result.externalReferences = externalReferences();
    result.finished = true;
  } catch (error) {
    result.exception = String(error && error.stack ? error.stack : error);
  }
  const pre = document.createElement("pre");
  pre.id = "selftest-result";
  pre.textContent = JSON.stringify(result, null, 2);
  document.body.appendChild(pre);

  // Errors can still come from timers and frames after the checks: write the result
  // again a second later, with whatever was recorded meanwhile. (A plain timer: under
  // a headless browser's virtual time, frames requested from timers may come late.)
  setTimeout(() => {
    Viewer.renderNow();
    result.settled = true;
    pre.textContent = JSON.stringify(result, null, 2);
  }, 1000);
})();
