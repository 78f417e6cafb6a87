"use strict";
// The interactive part of the report: one synchronized view (zoom and pan) shared by
// every image panel and the A/B swipe canvas, exposure, error views, the colour legend
// and the pixel readout.
//
// A view is stored in image pixels, independent of canvas size: the image point at the
// canvas centre (cx, cy) and how many image pixels span the canvas width. Canvases of
// any size therefore show the same region, and zooming about the cursor is exact.

const Viewer = (() => {
  const data = JSON.parse(document.getElementById("report-data").textContent);
  const epsilon = data.relmseEpsilon;
  const luts = { viridis: Colormaps.lookupTable("viridis"), magma: Colormaps.lookupTable("magma") };

  /** Decoded images, index 0 the reference: {name, width, height, rgb, flip}. */
  const images = data.images.map((desc) => ({
    name: desc.name,
    width: desc.width,
    height: desc.height,
    rgb: desc.data ? Pixels.decodeFloats(document.getElementById(desc.data).textContent, data.precision) : null,
    flip: desc.flip ? Pixels.decodeFloats(document.getElementById(desc.flip).textContent, data.precision) : null,
  }));
  const reference = images[0];
  const refWidth = Math.max(reference.width, 1);
  const refHeight = Math.max(reference.height, 1);

  const state = {
    exposure: 0,
    mode: "image", // "image" | "relerr" | "flip"
    errLo: -4,
    errHi: 0,
    view: fitView(),
    hover: null, // {x, y} image pixel under the cursor, or null
    swipe: 0.5,
    a: 0,
    b: Math.min(1, images.length - 1),
  };

  function fitView() {
    return { cx: refWidth / 2, cy: refHeight / 2, span: refWidth };
  }

  // ---- Display layers: each image rendered once per display setting, at 1:1 ----

  /** Off-screen canvas per image, repainted when the display settings change. */
  const layers = images.map(() => ({ canvas: document.createElement("canvas"), key: null, note: "" }));

  function displayKey() {
    return [state.mode, state.exposure, state.errLo, state.errHi].join("|");
  }

  /** The mode image i is shown in: the reference always shows itself. */
  function modeOf(i) {
    return i === 0 ? "image" : state.mode;
  }

  function sameSizeAsReference(img) {
    return img.width === reference.width && img.height === reference.height && reference.rgb;
  }

  function layerFor(i) {
    const layer = layers[i];
    const key = displayKey();
    if (layer.key !== key) {
      paintLayer(images[i], modeOf(i), layer);
      layer.key = key;
    }
    return layer;
  }

  function paintLayer(img, mode, layer) {
    layer.note = "";
    if (!img.rgb || img.width === 0 || img.height === 0) {
      layer.canvas.width = 0;
      layer.note = "image data missing";
      return;
    }
    layer.canvas.width = img.width;
    layer.canvas.height = img.height;
    const ctx = layer.canvas.getContext("2d");
    const pixels = ctx.createImageData(img.width, img.height);
    if (mode === "relerr" && sameSizeAsReference(img)) {
      Pixels.paintRelativeError(pixels.data, img.rgb, reference.rgb, state.errLo, state.errHi, epsilon, luts.viridis);
    } else if (mode === "flip" && img.flip) {
      Pixels.paintFlip(pixels.data, img.flip, luts.magma);
    } else {
      // Error views that cannot be made show the image, with a note saying why.
      if (mode === "relerr") layer.note = "size differs from the reference: image shown";
      if (mode === "flip") layer.note = "no ꟻLIP map: image shown";
      Pixels.paintImage(pixels.data, img.rgb, state.exposure);
    }
    ctx.putImageData(pixels, 0, 0);
  }

  // ---- Drawing the shared view ----

  /** Canvas-pixel transform of the current view: canvas = image × scale + offset. */
  function viewTransform(canvas) {
    const scale = canvas.width / state.view.span;
    return {
      scale,
      ox: canvas.width / 2 - state.view.cx * scale,
      oy: canvas.height / 2 - state.view.cy * scale,
    };
  }

  function imageToCanvas(canvas, x, y) {
    const t = viewTransform(canvas);
    return { x: x * t.scale + t.ox, y: y * t.scale + t.oy };
  }

  function canvasToImage(canvas, x, y) {
    const t = viewTransform(canvas);
    return { x: (x - t.ox) / t.scale, y: (y - t.oy) / t.scale };
  }

  /** Draws layer i under the view; nearest-neighbour pixels once they are magnified. */
  function drawLayer(ctx, canvas, i) {
    const layer = layerFor(i);
    const t = viewTransform(canvas);
    if (layer.canvas.width > 0) {
      ctx.imageSmoothingEnabled = t.scale < 1;
      ctx.setTransform(t.scale, 0, 0, t.scale, t.ox, t.oy);
      ctx.drawImage(layer.canvas, 0, 0);
      ctx.setTransform(1, 0, 0, 1, 0, 0);
    }
    return layer;
  }

  function drawBackground(ctx, canvas) {
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.fillStyle = "#1e1e1e";
    ctx.fillRect(0, 0, canvas.width, canvas.height);
  }

  /** Crop outline and hovered-pixel box, in canvas space over everything else. */
  function drawOverlays(ctx, canvas) {
    const t = viewTransform(canvas);
    if (data.crop) {
      const c = data.crop;
      const p = imageToCanvas(canvas, c.x0, c.y0);
      ctx.save();
      ctx.setLineDash([5, 4]);
      ctx.strokeStyle = "rgba(255, 255, 255, 0.8)";
      ctx.strokeRect(p.x, p.y, (c.x1 - c.x0) * t.scale, (c.y1 - c.y0) * t.scale);
      ctx.restore();
    }
    if (state.hover && t.scale >= 6) {
      const p = imageToCanvas(canvas, state.hover.x, state.hover.y);
      ctx.strokeStyle = "#ffd000";
      ctx.strokeRect(p.x + 0.5, p.y + 0.5, t.scale - 1, t.scale - 1);
    }
  }

  function drawNote(ctx, canvas, text, y) {
    if (!text) return;
    ctx.font = Math.round(12 * (window.devicePixelRatio || 1)) + "px sans-serif";
    ctx.fillStyle = "rgba(0, 0, 0, 0.6)";
    const w = ctx.measureText(text).width;
    ctx.fillRect(4, y - 14, w + 8, 18);
    ctx.fillStyle = "#fff";
    ctx.fillText(text, 8, y);
  }

  const panels = Array.from(document.querySelectorAll("#panels .panel")).map((figure) => ({
    index: Number(figure.dataset.image),
    canvas: figure.querySelector("canvas"),
    readout: figure.querySelector(".readout"),
  }));
  const swipeCanvas = document.getElementById("swipe-canvas");

  function drawPanel(panel) {
    const ctx = panel.canvas.getContext("2d");
    drawBackground(ctx, panel.canvas);
    const layer = drawLayer(ctx, panel.canvas, panel.index);
    drawOverlays(ctx, panel.canvas);
    drawNote(ctx, panel.canvas, layer.note, panel.canvas.height - 8);
  }

  /** A left of the split, B right of it; the split is a fraction of the canvas width. */
  function drawSwipe() {
    const canvas = swipeCanvas;
    const ctx = canvas.getContext("2d");
    drawBackground(ctx, canvas);
    const layerA = drawLayer(ctx, canvas, state.a);
    const split = Math.round(state.swipe * canvas.width);
    ctx.save();
    ctx.beginPath();
    ctx.rect(split, 0, canvas.width - split, canvas.height);
    ctx.clip();
    drawBackground(ctx, canvas);
    const layerB = drawLayer(ctx, canvas, state.b);
    ctx.restore();
    drawOverlays(ctx, canvas);
    if (split > 0 && split < canvas.width) {
      ctx.fillStyle = "#fff";
      ctx.fillRect(split - 1, 0, 2, canvas.height);
    }
    const h = canvas.height;
    drawNote(ctx, canvas, "A: " + images[state.a].name + (layerA.note ? " (" + layerA.note + ")" : ""), h - 28);
    drawNote(ctx, canvas, "B: " + images[state.b].name + (layerB.note ? " (" + layerB.note + ")" : ""), h - 8);
  }

  // ---- Readout of the pixel under the cursor ----

  function format(v) {
    return Number.isFinite(v) ? v.toPrecision(4) : String(v);
  }

  /** Text for image i at the hovered pixel, in the units of its current mode. */
  function readoutText(i) {
    const img = images[i];
    const h = state.hover;
    if (!h || !img.rgb || h.x >= img.width || h.y >= img.height) return "";
    const p = h.y * img.width + h.x;
    const mode = modeOf(i);
    if (mode === "relerr" && sameSizeAsReference(img)) {
      return "rel. sq. error " + format(Pixels.relativeSquaredError(img.rgb, reference.rgb, p, epsilon));
    }
    if (mode === "flip" && img.flip) {
      return "ꟻLIP " + format(img.flip[p]);
    }
    const rgb = img.rgb;
    return "R " + format(rgb[3 * p]) + "  G " + format(rgb[3 * p + 1]) + "  B " + format(rgb[3 * p + 2]);
  }

  function updateReadouts() {
    const h = state.hover;
    document.getElementById("hover-position").textContent = h ? "pixel (" + h.x + ", " + h.y + ")" : "";
    for (const panel of panels) {
      panel.readout.textContent = readoutText(panel.index);
    }
    const swipeText = h ? "A: " + readoutText(state.a) + "   |   B: " + readoutText(state.b) : "";
    document.getElementById("swipe-readout").textContent = swipeText;
  }

  // ---- Legend ----

  function updateLegend() {
    const legend = document.getElementById("legend");
    legend.hidden = state.mode === "image";
    document.getElementById("error-range").hidden = state.mode !== "relerr";
    if (legend.hidden) return;
    const name = state.mode === "flip" ? "magma" : "viridis";
    const bar = document.getElementById("legend-bar");
    const ctx = bar.getContext("2d");
    for (let x = 0; x < bar.width; x++) {
      const c = Colormaps.sample(name, x / (bar.width - 1));
      ctx.fillStyle = "rgb(" + c.join(",") + ")";
      ctx.fillRect(x, 0, 1, bar.height);
    }
    let ticks;
    if (state.mode === "flip") {
      document.getElementById("legend-title").textContent = "ꟻLIP error (0 = no visible difference, 1 = maximal)";
      ticks = [0, 0.25, 0.5, 0.75, 1].map((v) => ({ t: v, label: String(v) }));
    } else {
      document.getElementById("legend-title").textContent =
        "relative squared error (a−b)²/(b²+" + epsilon + "), mean of R, G, B — log scale";
      ticks = [];
      for (let k = state.errLo; k <= state.errHi; k++) {
        ticks.push({ t: (k - state.errLo) / Math.max(state.errHi - state.errLo, 1), label: "1e" + k });
      }
    }
    const box = document.getElementById("legend-ticks");
    box.replaceChildren(
      ...ticks.map((tick) => {
        const span = document.createElement("span");
        span.style.left = 100 * tick.t + "%";
        span.textContent = tick.label;
        return span;
      }),
    );
  }

  // ---- Rendering, coalesced into animation frames ----

  let framePending = false;

  function renderNow() {
    framePending = false;
    for (const panel of panels) drawPanel(panel);
    drawSwipe();
    updateReadouts();
  }

  function requestRender() {
    if (!framePending) {
      framePending = true;
      requestAnimationFrame(() => framePending && renderNow());
    }
  }

  /** Sizes each canvas's backing store to its CSS size × device pixel ratio. */
  function resizeCanvases() {
    const dpr = window.devicePixelRatio || 1;
    for (const canvas of [...panels.map((p) => p.canvas), swipeCanvas]) {
      canvas.style.aspectRatio = refWidth + " / " + refHeight;
      canvas.width = Math.max(1, Math.round(canvas.clientWidth * dpr));
      canvas.height = Math.max(1, Math.round((canvas.width * refHeight) / refWidth));
    }
    requestRender();
  }

  // ---- Input ----

  /** The event position in canvas backing-store pixels. */
  function eventPoint(canvas, event) {
    const r = canvas.getBoundingClientRect();
    return {
      x: ((event.clientX - r.left) * canvas.width) / r.width,
      y: ((event.clientY - r.top) * canvas.height) / r.height,
    };
  }

  function setHover(canvas, point) {
    const p = canvasToImage(canvas, point.x, point.y);
    const x = Math.floor(p.x);
    const y = Math.floor(p.y);
    state.hover = x >= 0 && y >= 0 && x < refWidth && y < refHeight ? { x, y } : null;
  }

  /** Zooms by `factor` keeping the image point under canvas point `point` in place. */
  function zoomAbout(canvas, point, factor) {
    const anchor = canvasToImage(canvas, point.x, point.y);
    const span = Math.min(Math.max(state.view.span / factor, 2), 8 * Math.max(refWidth, refHeight));
    const scale = canvas.width / span;
    state.view = {
      span,
      cx: anchor.x - (point.x - canvas.width / 2) / scale,
      cy: anchor.y - (point.y - canvas.height / 2) / scale,
    };
  }

  function attachViewInput(canvas) {
    let drag = null;
    canvas.addEventListener(
      "wheel",
      (event) => {
        event.preventDefault();
        // deltaMode 1 counts lines; about 16 pixels each.
        const dy = event.deltaMode === 1 ? 16 * event.deltaY : event.deltaY;
        zoomAbout(canvas, eventPoint(canvas, event), Math.exp(-dy * 0.002));
        setHover(canvas, eventPoint(canvas, event));
        requestRender();
      },
      { passive: false },
    );
    canvas.addEventListener("pointerdown", (event) => {
      drag = eventPoint(canvas, event);
      try {
        // Keeps the drag going when the pointer leaves the canvas.
        canvas.setPointerCapture(event.pointerId);
      } catch (error) {
        // Synthetic events have no capturable pointer; dragging still works inside.
      }
      canvas.classList.add("dragging");
    });
    canvas.addEventListener("pointermove", (event) => {
      const point = eventPoint(canvas, event);
      if (drag) {
        const scale = viewTransform(canvas).scale;
        state.view = {
          ...state.view,
          cx: state.view.cx - (point.x - drag.x) / scale,
          cy: state.view.cy - (point.y - drag.y) / scale,
        };
        drag = point;
      }
      setHover(canvas, point);
      requestRender();
    });
    const endDrag = () => {
      drag = null;
      canvas.classList.remove("dragging");
    };
    canvas.addEventListener("pointerup", endDrag);
    canvas.addEventListener("pointercancel", endDrag);
    canvas.addEventListener("pointerleave", () => {
      if (!drag) {
        state.hover = null;
        requestRender();
      }
    });
    canvas.addEventListener("dblclick", () => {
      state.view = fitView();
      requestRender();
    });
  }

  function bindControls() {
    const exposure = document.getElementById("exposure");
    exposure.addEventListener("input", () => {
      state.exposure = Number(exposure.value);
      const v = state.exposure;
      document.getElementById("exposure-value").textContent = (v >= 0 ? "+" : "") + v.toFixed(1) + " EV";
      requestRender();
    });
    const mode = document.getElementById("display-mode");
    mode.addEventListener("change", () => {
      state.mode = mode.value;
      updateLegend();
      requestRender();
    });
    for (const id of ["err-lo", "err-hi"]) {
      document.getElementById(id).addEventListener("input", () => {
        const lo = Math.round(Number(document.getElementById("err-lo").value));
        const hi = Math.round(Number(document.getElementById("err-hi").value));
        if (Number.isFinite(lo) && Number.isFinite(hi) && lo < hi) {
          state.errLo = lo;
          state.errHi = hi;
          updateLegend();
          requestRender();
        }
      });
    }
    document.getElementById("view-reset").addEventListener("click", () => {
      state.view = fitView();
      requestRender();
    });
    const bindSelect = (id, key) => {
      const select = document.getElementById(id);
      select.addEventListener("change", () => {
        state[key] = Number(select.value);
        requestRender();
      });
    };
    bindSelect("swipe-a", "a");
    bindSelect("swipe-b", "b");
    const swipe = document.getElementById("swipe-position");
    swipe.addEventListener("input", () => {
      state.swipe = Number(swipe.value) / Number(swipe.max);
      requestRender();
    });
  }

  for (const panel of panels) attachViewInput(panel.canvas);
  attachViewInput(swipeCanvas);
  bindControls();
  window.addEventListener("resize", resizeCanvases);
  resizeCanvases();
  renderNow();

  // What the self-test needs to see inside.
  return { data, images, state, panels, swipeCanvas, renderNow, imageToCanvas, fitView };
})();
