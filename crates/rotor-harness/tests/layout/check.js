// Runs in headless Chromium after layout: for every inline <svg> of the page (each carries
// its file name in data-name), the boxes of its non-empty <text> elements in the figure's
// own coordinates, which of them reach outside the figure, and which pairs overlap by more
// than a pixel each way. The result goes into <pre id="layout"> as JSON, for --dump-dom.
function textBoxes(svg) {
  const toSvg = svg.getScreenCTM().inverse();
  return [...svg.querySelectorAll('text')]
    .filter((t) => t.textContent.trim() !== '')
    .map((t) => {
      const b = t.getBBox();
      const m = toSvg.multiply(t.getScreenCTM());
      const corners = [[b.x, b.y], [b.x + b.width, b.y], [b.x, b.y + b.height], [b.x + b.width, b.y + b.height]]
        .map(([x, y]) => new DOMPoint(x, y).matrixTransform(m));
      const xs = corners.map((p) => p.x);
      const ys = corners.map((p) => p.y);
      return { text: t.textContent, x0: Math.min(...xs), x1: Math.max(...xs), y0: Math.min(...ys), y1: Math.max(...ys) };
    });
}

function check() {
  const out = [];
  document.querySelectorAll('svg[data-name]').forEach((svg) => {
    const vb = svg.viewBox.baseVal;
    const boxes = textBoxes(svg);
    const outside = boxes
      .filter((b) => b.x0 < vb.x - 0.5 || b.y0 < vb.y - 0.5 || b.x1 > vb.x + vb.width + 0.5 || b.y1 > vb.y + vb.height + 0.5)
      .map((b) => b.text);
    const overlaps = [];
    for (let i = 0; i < boxes.length; i++) {
      for (let j = i + 1; j < boxes.length; j++) {
        const a = boxes[i];
        const c = boxes[j];
        const ox = Math.min(a.x1, c.x1) - Math.max(a.x0, c.x0);
        const oy = Math.min(a.y1, c.y1) - Math.max(a.y0, c.y0);
        if (ox > 1 && oy > 1) overlaps.push([a.text, c.text]);
      }
    }
    out.push({ name: svg.getAttribute('data-name'), texts: boxes.length, outside, overlaps });
  });
  const pre = document.createElement('pre');
  pre.id = 'layout';
  pre.textContent = JSON.stringify(out);
  document.body.appendChild(pre);
}

window.addEventListener('load', check);
