"""The interactive viewer's style sheet and script (:mod:`pcmapq.report.viewer` writes its
SVG): the sizes of its marks in screen pixels and the colour of each feature status."""

from __future__ import annotations

from pcmapq.report.style import EXTRA, MATCHED, MISSING

#: Radius of a feature's circle, screen pixels, at every zoom.
R_PX = 4
#: The features crowd while the median distance from one to its nearest other is under this
#: many screen pixels (two radii: their circles overlap) ...
CROWDED_PX = 2 * R_PX
#: ... over thin walls: a cell under this many screen pixels (a wall a few cells thick is then
#: narrower than a circle, which shows around it). Both hold: walls over features, as rings.
SMALL_CELL_PX = R_PX / 2
#: What each status means, in the tooltip and beside its checkbox.
STATUSES = {"matched": "matched", "missing": "missing (truth, no map partner)",
            "extra": "extra (map, no truth partner)"}
COLOURS = {"matched": MATCHED, "missing": MISSING, "extra": EXTRA}

STYLE = """
.viewer { position: relative; border: 1px solid #ddd; }
.viewer svg { display: block; width: 100%; height: auto; max-height: 80vh; background: #fff;
              cursor: grab; touch-action: none; user-select: none; }
.viewer svg.dragging { cursor: grabbing; }
.viewer circle { r: var(--r, 3px); vector-effect: non-scaling-stroke; pointer-events: all;
                 stroke-width: 2; }
.viewer line { vector-effect: non-scaling-stroke; pointer-events: none; }
.viewer .arrow { stroke: #000; stroke-width: 1.5; }
.viewer image { image-rendering: pixelated; pointer-events: none; }
#viewer-tip { position: absolute; pointer-events: none; background: rgba(255,255,255,0.95);
              border: 1px solid #888; padding: 0.3em 0.5em; font-size: 0.85em;
              white-space: pre; display: none; }
.controls { font-size: 0.9em; margin: 0.5em 0; } .controls td { text-align: left; }
.controls label { white-space: nowrap; }
""" + "".join(
    f'.viewer g[id$="-{status}"] circle {{ fill: {colour}; stroke: {colour}; }}\n'
    f'.viewer g[id$="-{status}"] .segment {{ stroke: {colour}; stroke-width: 2; }}\n'
    for status, colour in COLOURS.items()) + """\
.viewer g[id$="-missing"] circle, .viewer g[id$="-extra"] circle { fill-opacity: 0.25; }
.viewer svg.crowded g circle { fill-opacity: 0.15; stroke-width: 1.5; }
.viewer svg.crowded g .segment { stroke-width: 1; stroke-opacity: 0.6; }
.viewer svg.crowded g .arrow { stroke-width: 1; stroke-opacity: 0.6; }
.viewer svg g circle:hover, .viewer svg g circle.pinned { stroke: #000; stroke-width: 3; }
"""

#: The script's own copies of the sizes above.
SIZES = (f"const R_PX = {R_PX:g}, CROWDED_PX = {CROWDED_PX:g}, "
         f"SMALL_CELL_PX = {SMALL_CELL_PX:g};")

SCRIPT = """
(function () {
  """ + SIZES + """
  const svg = document.getElementById('viewer-svg');
  const tip = document.getElementById('viewer-tip');
  const home = svg.getAttribute('viewBox');
  let box = home.split(' ').map(Number);
  const walls = [document.getElementById('walls-map'), document.getElementById('walls-truth')];
  const spacing = Number(svg.dataset.spacing);
  function show() {
    svg.setAttribute('viewBox', box.join(' '));
    const ctm = svg.getScreenCTM();
    if (!ctm || !(ctm.a > 0)) return;
    svg.style.setProperty('--r', (R_PX / ctm.a) + 'px');
    const crowded = spacing * ctm.a < CROWDED_PX && ctm.a < SMALL_CELL_PX;
    if (crowded !== svg.classList.contains('crowded')) {
      svg.classList.toggle('crowded', crowded);
      if (crowded) svg.append(...walls); else svg.prepend(...walls);
    }
  }
  function toUser(x, y) {
    const p = new DOMPoint(x, y).matrixTransform(svg.getScreenCTM().inverse());
    return [p.x, p.y];
  }
  svg.addEventListener('wheel', function (e) {
    e.preventDefault();
    const [ux, uy] = toUser(e.clientX, e.clientY);
    const k = Math.pow(1.0015, e.deltaY);
    box = [ux - (ux - box[0]) * k, uy - (uy - box[1]) * k, box[2] * k, box[3] * k];
    show();
  }, {passive: false});
  let drag = null;
  let dragged = false;
  svg.addEventListener('pointerdown', function (e) {
    drag = {x: e.clientX, y: e.clientY, box: box.slice(), px: svg.getScreenCTM().a, moved: 0};
    dragged = false;
    svg.classList.add('dragging');
  });
  svg.addEventListener('pointermove', function (e) {
    if (!drag) return;
    const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
    drag.moved = Math.max(drag.moved, Math.abs(dx) + Math.abs(dy));
    box = [drag.box[0] - dx / drag.px, drag.box[1] - dy / drag.px, box[2], box[3]];
    show();
  });
  function release(moved) {
    dragged = moved && drag !== null && drag.moved > 3;
    drag = null;
    svg.classList.remove('dragging');
  }
  svg.addEventListener('pointerup', function () { release(true); });
  svg.addEventListener('pointerleave', function () { release(false); });
  const labels = JSON.parse(svg.dataset.labels);
  const m = function (v) { return v + ' m'; };
  function describe(c) {
    const d = c.dataset;
    const lines = [d.detector + ': ' + labels[d.status], 'x ' + m(d.x) + ', y ' + m(d.y)];
    if (d.status === 'matched') {
      lines.push('map feature: x ' + m(d.mapX) + ', y ' + m(d.mapY));
      lines.push('displacement ' + m(d.displacement) + ' (dx ' + d.dx + ', dy ' + d.dy + ' m)');
    } else {
      lines.push('displacement: none (unmatched); nearest ' +
                 (d.status === 'missing' ? 'map' : 'truth') + ' feature: ' +
                 (d.nearest ? m(d.nearest) : 'none'));
    }
    if (d.room) lines.push(d.room);
    return lines.join('\\n');
  }
  let pinned = null;
  function place(c, e) {
    tip.textContent = describe(c);
    tip.style.display = 'block';
    const frame = svg.parentNode.getBoundingClientRect();
    tip.style.left = (e.clientX - frame.left + 12) + 'px';
    tip.style.top = (e.clientY - frame.top + 12) + 'px';
  }
  svg.addEventListener('mouseover', function (e) {
    if (!pinned && e.target.tagName === 'circle') place(e.target, e);
  });
  svg.addEventListener('mouseout', function (e) {
    if (!pinned && e.target.tagName === 'circle') tip.style.display = 'none';
  });
  svg.addEventListener('click', function (e) {
    if (dragged) { dragged = false; return; }
    if (pinned) pinned.classList.remove('pinned');
    pinned = e.target.tagName === 'circle' ? e.target : null;
    if (pinned) { pinned.classList.add('pinned'); place(pinned, e); }
    else tip.style.display = 'none';
  });
  document.querySelectorAll('.controls input[data-layer]').forEach(function (input) {
    input.addEventListener('change', function () {
      document.getElementById(input.dataset.layer)
        .setAttribute('display', input.checked ? 'inline' : 'none');
    });
  });
  document.getElementById('viewer-reset').addEventListener('click', function () {
    box = home.split(' ').map(Number); show();
  });
  window.addEventListener('resize', show);
  show();
})();
"""
