#!/bin/sh
# Screenshots of a `radiant study` report for the docs, with headless Chromium:
#   tools/study/screenshots.sh report.html OUTDIR
# writes OUTDIR/study-{header,images,flip,swipe,table,plots}.png. A copy of the report gets a
# small script that, by URL fragment, picks a view and hides the other sections (the
# report itself is not changed).
set -eu
report=$1
out=$2
chromium=${RADIANT_CHROMIUM:-chromium}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
page=$tmp/page.html
sed 's|</body>|<script>\
(() => {\
  const view = location.hash.slice(1);\
  const set = (id, v, ev) => { const e = document.getElementById(id); e.value = v; e.dispatchEvent(new Event(ev, { bubbles: true })); };\
  const keep = { images: ["controls", "viewer"], flip: ["controls", "viewer"], relerr: ["controls", "viewer"],\
    swipe: ["swipe"], table: ["metrics-section"], plots: ["convergence"], header: ["header"] }[view];\
  if (!keep) return;\
  for (const e of document.body.children) {\
    const id = e.id \|\| e.tagName.toLowerCase();\
    if (e.tagName !== "SCRIPT" \&\& !keep.includes(id)) e.style.display = "none";\
  }\
  if (view === "flip") set("display-mode", "flip", "change");\
  if (view === "relerr") set("display-mode", "relerr", "change");\
  if (view === "swipe") { set("swipe-b", "1", "change"); set("swipe-position", "420", "input"); }\
  window.dispatchEvent(new Event("resize"));\
})();\
</script>\n</body>|' "$report" > "$page"
shot() {
  "$chromium" --headless --no-sandbox --disable-gpu --disable-quic --no-first-run \
    --disable-background-networking --disable-component-update --disable-sync \
    --user-data-dir="$tmp/profile" --hide-scrollbars --virtual-time-budget=5000 \
    --force-device-scale-factor=0.6 \
    --window-size="$3" --screenshot="$out/$1" "file://$page#$2" 2>/dev/null
}
shot study-header.png header 1650,230
shot study-images.png images 1650,900
shot study-flip.png flip 1650,900
shot study-swipe.png swipe 1650,480
shot study-table.png table 1650,300
shot study-plots.png plots 1500,820
