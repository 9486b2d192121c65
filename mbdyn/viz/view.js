/* mbdyn's HTML view: rebuilds every frame from the movers' poses (mbdyn/viz/view_data.py)
   and draws it with WebGL (view_gl.js) or, without it, a 2D canvas (view_2d.js).  A
   turntable camera about the model's up direction: drag to orbit, wheel to zoom, shift-drag
   or right-drag to pan, double-click or "reset view" to fit the run again.  Texts a user
   named (title, bodies, mounts) reach the page through textContent only.  Exposes
   window.mbdynView: frames, times (s), names, goto(i) (a promise), positions() (the drawn
   centres of mass, world axes), project(p) (CSS pixels in the canvas), renderer. */
var SHADE = {ambient: 0.45, diffuse: 0.6}, PLANE_ALPHA = 0.3, FOV = 30 * Math.PI / 180;
var D = JSON.parse(document.getElementById("mbdyn-data").textContent);
var U = D.unit, NT = D.times.length, NM = D.movers;
var pose = new Float64Array(NT * NM * 12);          // per frame and mover: R (9), r (3)
(function () {
  for (var k = 0; k < NT * NM; k++) {
    var o = k * 7, w = D.poses[o + 3], x = D.poses[o + 4], y = D.poses[o + 5],
      z = D.poses[o + 6], s = 2 / (w * w + x * x + y * y + z * z), p = k * 12;
    pose.set([1 - s * (y * y + z * z), s * (x * y - w * z), s * (x * z + w * y),
      s * (x * y + w * z), 1 - s * (x * x + z * z), s * (y * z - w * x),
      s * (x * z - w * y), s * (y * z + w * x), 1 - s * (x * x + y * y),
      D.poses[o] * U, D.poses[o + 1] * U, D.poses[o + 2] * U], p);
  }
})();
function at(k, a) {                        // a = [mover, x, y, z] (ints) -> world point
  var x = a[1] * U, y = a[2] * U, z = a[3] * U;
  if (a[0] < 0) return [x, y, z];
  var p = (k * NM + a[0]) * 12, R = pose;
  return [R[p + 9] + R[p] * x + R[p + 1] * y + R[p + 2] * z,
    R[p + 10] + R[p + 3] * x + R[p + 4] * y + R[p + 5] * z,
    R[p + 11] + R[p + 6] * x + R[p + 7] * y + R[p + 8] * z];
}
function sub(a, b) { return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]; }
function dot(a, b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
function cross(a, b) {
  return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
}
function unit(a) { var n = Math.hypot(a[0], a[1], a[2]) || 1; return [a[0] / n, a[1] / n, a[2] / n]; }
function comb(m, a, b, ca, cb) {          // m + ca a + cb b
  return [m[0] + ca * a[0] + cb * b[0], m[1] + ca * a[1] + cb * b[1], m[2] + ca * a[2] + cb * b[2]];
}
function lerp(a, b, s) { return comb(a, a, b, -s, s); }
function scaled(ints, i) { return [ints[i] * U, ints[i + 1] * U, ints[i + 2] * U]; }
var swatch = document.createElement("canvas").getContext("2d"), colours = {};
function rgb(colour) {                     // any CSS colour -> [r, g, b] in 0..1 (grey if unknown)
  if (colours[colour]) return colours[colour];
  swatch.fillStyle = "#808080"; swatch.fillStyle = String(colour);
  var m = /^#([0-9a-f]{2})([0-9a-f]{2})([0-9a-f]{2})$/i.exec(swatch.fillStyle);
  colours[colour] = m ? [1, 2, 3].map(function (i) { return parseInt(m[i], 16) / 255; })
    : [0.5, 0.5, 0.5];
  return colours[colour];
}
// ---- the static scene: triangles with their face normals (solids in their mover's axes)
function triangles(m, scale) {
  var v = m.v, f = m.f, tri = new Float32Array(f.length * 3), nrm = new Float32Array(f.length * 3);
  for (var i = 0; i < f.length; i += 3) {
    var p = [0, 1, 2].map(function (j) {
      var o = 3 * f[i + j];
      return [v[o] * scale, v[o + 1] * scale, v[o + 2] * scale];
    });
    var n = unit(cross(sub(p[1], p[0]), sub(p[2], p[0])));
    for (var j = 0; j < 3; j++) { tri.set(p[j], 3 * (i + j)); nrm.set(n, 3 * (i + j)); }
  }
  return {tri: tri, nrm: nrm, rgb: rgb(m.color), mover: m.mover};
}
var solids = D.solids.map(function (s) { return triangles(s, U); });
var planes = D.planes.map(function (p) { return triangles(p, U); });
var axisOrigin = scaled(D.axes.origin, 0);
var axisTips = [0, 1, 2].map(function (i) {
  var t = axisOrigin.slice(); t[i] += D.axes.length * U; return t;
});
// ---- one frame: the movers' poses, line segments by style, markers
var com = [];                             // centres of mass of every frame (trails, markers)
for (var k = 0; k < NT; k++) com.push(D.markers.map(function (m) { return at(k, m.at); }));
function coil(out, a, b, radius) {        // as viz.drawing.coil: leads of a tenth, 8 turns
  var e = unit(sub(b, a)), h = Math.abs(e[0]) < 0.6 ? [1, 0, 0] : [0, 1, 0];
  var q1 = unit(cross(h, e)), q2 = cross(e, q1), prev = lerp(a, b, 0.1), n = 96;
  out.push(a[0], a[1], a[2], prev[0], prev[1], prev[2]);
  for (var i = 0; i <= n; i++) {
    var s = i / n, ph = 2 * Math.PI * 8 * s;
    var p = comb(lerp(a, b, 0.1 + 0.8 * s), q1, q2, Math.cos(ph) * radius, Math.sin(ph) * radius);
    out.push(prev[0], prev[1], prev[2], p[0], p[1], p[2]); prev = p;
  }
  var end = lerp(a, b, 0.9);
  polyline(out, [prev, end, b]);
}
function polyline(out, pts) {             // as segments: a, b of each, one after the other
  for (var i = 1; i < pts.length; i++) {
    out.push(pts[i - 1][0], pts[i - 1][1], pts[i - 1][2], pts[i][0], pts[i][1], pts[i][2]);
  }
}
function frameAt(k) {
  var styles = {}, marks = [];
  function lines(colour, width) {          // width in CSS pixels
    var key = colour + "/" + width;
    if (!styles[key]) styles[key] = {rgb: rgb(colour), width: width, pts: []};
    return styles[key].pts;
  }
  D.groups.forEach(function (g) {
    var out = lines(g.color, 2 * g.width);
    g.lines.forEach(function (pts) { polyline(out, pts.map(function (a) { return at(k, a); })); });
  });
  D.springs.forEach(function (s) {
    coil(lines(D.colors.spring, 3), at(k, s[0]), at(k, s[1]), D.sizes.coil * U);
  });
  D.dampers.forEach(function (s) {
    var a = at(k, s[0]), b = at(k, s[1]);
    polyline(lines(D.colors.damper, 14), [a, lerp(a, b, 0.55)]);
    polyline(lines(D.colors.damper, 5), [lerp(a, b, 0.4), b]);
  });
  var k0 = Math.max(0, k - D.trail + 1), trail = lines(D.colors.trail, 1.2), i;
  D.markers.forEach(function (m, n) {
    var pts = []; for (i = k0; i <= k; i++) pts.push(com[i][n]);
    polyline(trail, pts);
  });
  D.points.forEach(function (p) {
    var pts = []; for (i = k0; i <= k; i++) pts.push(scaled(p, 3 * i));
    polyline(trail, pts);
  });
  var a = D.arrows.length ? D.arrows[k] : [];
  for (i = 0; i < a.length; i += 6) polyline(lines(D.colors.force, 5), [scaled(a, i), scaled(a, i + 3)]);
  axisTips.forEach(function (t, n) { polyline(lines(D.axes.colors[n], 2), [axisOrigin, t]); });
  D.tags.forEach(function (t) { marks.push({p: at(k, t.at), rgb: rgb(t.color), size: 18, shape: 1}); });
  D.markers.forEach(function (m, n) {
    marks.push({p: com[k][n], rgb: rgb(m.color), size: 1.5 * m.size, shape: 0});
  });
  return {poses: pose.subarray(k * NM * 12, (k + 1) * NM * 12), marks: marks,
    lines: Object.keys(styles).map(function (key) { return styles[key]; })};
}
// ---- the camera's fit: the run's mechanism (every piece at every pose), the world axes and
// the contact-force arrows; ground planes may reach past it
function extent() {
  var lo = scaled(D.box[0], 0), hi = scaled(D.box[1], 0);
  function add(p) {
    for (var i = 0; i < 3; i++) { lo[i] = Math.min(lo[i], p[i]); hi[i] = Math.max(hi[i], p[i]); }
  }
  axisTips.concat([axisOrigin]).forEach(add);
  D.arrows.forEach(function (a) { for (var i = 0; i < a.length; i += 3) add(scaled(a, i)); });
  var corners = [0, 1, 2, 3, 4, 5, 6, 7].map(function (c) {
    return [c & 1 ? hi[0] : lo[0], c & 2 ? hi[1] : lo[1], c & 4 ? hi[2] : lo[2]];
  });
  return {centre: lerp(lo, hi, 0.5), corners: corners,
    radius: Math.max(0.5 * Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]), U)};
}
function fitDistance(axes, tx, ty) {       // the nearest eye that sees every corner of the fit
  var d = 0;
  fit.corners.forEach(function (c) {
    var v = sub(c, fit.centre), z = dot(axes[2], v);
    d = Math.max(d, z + Math.abs(dot(axes[0], v)) / tx, z + Math.abs(dot(axes[1], v)) / ty);
  });
  return Math.max(d, 2 * fit.radius / 50);
}
var fit = extent();
// ---- the camera: a turntable about "up" (D.basis: two level axes, then up), perspective
var plot = document.getElementById("mbdyn-plot"), canvas = document.getElementById("mbdyn-canvas");
var B = D.basis, view = {}, cam = {};
function reset() {
  var d = D.eye, a = [dot(d, B[0]), dot(d, B[1]), dot(d, B[2])];
  view = {target: fit.centre.slice(), az: Math.atan2(a[1], a[0]),
    el: Math.asin(Math.max(-1, Math.min(1, a[2] / Math.hypot(a[0], a[1], a[2])))), fitted: true};
}
function camera() {                       // cam: vp (GL, about the origin O), light, screen(p)
  var W = canvas.clientWidth || 1, H = canvas.clientHeight || 1, aspect = W / H;
  var ce = Math.cos(view.el);
  var d = comb([0, 0, 0], B[0], B[1], ce * Math.cos(view.az), ce * Math.sin(view.az));
  d = comb(d, B[2], B[2], Math.sin(view.el), 0);
  var zc = d, xc = unit(cross(B[2], zc)), yc = cross(zc, xc), V = [xc, yc, zc];
  if (view.fitted) view.dist = fitDistance(V, 0.9 * aspect * Math.tan(FOV / 2), 0.9 * Math.tan(FOV / 2));
  var eye = comb(view.target, d, d, view.dist, 0);
  var f = 1 / Math.tan(FOV / 2), near = view.dist / 50, far = view.dist + 20 * fit.radius;
  var O = fit.centre, t = sub(eye, O);
  var vp = new Float32Array(16), P = [f / aspect, f, (far + near) / (near - far)];
  for (var j = 0; j < 3; j++) {           // column j of P V (V's rows xc, yc, zc)
    vp[4 * j] = P[0] * xc[j]; vp[4 * j + 1] = P[1] * yc[j];
    vp[4 * j + 2] = P[2] * zc[j]; vp[4 * j + 3] = -zc[j];
  }
  var tv = V.map(function (r) { return -dot(r, t); });
  vp[12] = P[0] * tv[0]; vp[13] = P[1] * tv[1];
  vp[14] = P[2] * tv[2] + 2 * far * near / (near - far); vp[15] = -tv[2];
  var light = unit(comb(zc, xc, yc, -0.35, 0.45));     // over the viewer's left shoulder
  cam = {vp: vp, light: light, width: canvas.width, height: canvas.height, near: near,
    dpr: canvas.width / W, axes: V, scale: 2 * Math.tan(FOV / 2) / H,
    screen: function (p) {                // -> [x, y] in CSS pixels of the canvas, depth
      var v = sub(p, eye), z = -dot(zc, v);
      return [W / 2 * (1 + f / aspect * dot(xc, v) / z), H / 2 * (1 - f * dot(yc, v) / z), z];
    }};
  return cam;
}
// ---- drawing, and the texts over the canvas (textContent only)
var renderer = glRenderer(canvas) || canvasRenderer(canvas);
renderer.setScene(solids, planes, fit.centre);
var overlay = document.getElementById("mbdyn-labels"), tip = document.getElementById("mbdyn-tip");
function label(text, cls, colour) {
  var e = document.createElement("span");
  e.className = cls; e.textContent = text;
  if (colour) e.style.color = colour;
  overlay.appendChild(e);
  return e;
}
document.getElementById("mbdyn-title").textContent = D.title;
document.getElementById("mbdyn-scale").textContent = "world axes: " + D.axes.caption;
var bodyLabels = D.names.map(function (n) { return label(n, "mbdyn-label"); });
var axisLabels = ["x", "y", "z"].map(function (n, i) {
  return label(n, "mbdyn-axis", D.axes.colors[i]);
});
function place(e, p, dx, dy) {
  var s = cam.screen(p);
  e.style.visibility = s[2] > cam.near ? "visible" : "hidden";
  e.style.transform = "translate(" + (s[0] + dx).toFixed(1) + "px," + (s[1] + dy).toFixed(1) + "px)";
}
var current = 0, drawn = null, pending = false;
function render() {
  pending = false;
  var W = Math.max(1, Math.round(canvas.clientWidth * (window.devicePixelRatio || 1)));
  var H = Math.max(1, Math.round(canvas.clientHeight * (window.devicePixelRatio || 1)));
  if (canvas.width !== W || canvas.height !== H) { canvas.width = W; canvas.height = H; }
  camera();
  drawn = frameAt(current);
  renderer.draw(cam, drawn);
  bodyLabels.forEach(function (e, n) { place(e, com[current][n], 7, -18); });
  axisLabels.forEach(function (e, n) { place(e, axisTips[n], 3, -8); });
}
function redraw() { if (!pending) { pending = true; requestAnimationFrame(render); } }
// ---- orbit (drag), pan (shift-drag, right-drag), zoom (wheel), reset (double-click, button)
var drag = null;
canvas.addEventListener("pointerdown", function (e) {
  drag = {x: e.clientX, y: e.clientY, pan: e.shiftKey || e.button === 2};
  canvas.setPointerCapture(e.pointerId);
});
canvas.addEventListener("pointermove", function (e) {
  if (!drag) { hover(e); return; }
  var dx = e.clientX - drag.x, dy = e.clientY - drag.y;
  drag.x = e.clientX; drag.y = e.clientY;
  if (drag.pan) {
    var s = view.dist * cam.scale;
    view.target = comb(view.target, cam.axes[0], cam.axes[1], -dx * s, dy * s);
  } else {
    view.az -= dx * 0.008;
    view.el = Math.max(-1.55, Math.min(1.55, view.el + dy * 0.008));
  }
  view.fitted = false; redraw();
});
canvas.addEventListener("pointerup", function () { drag = null; });
canvas.addEventListener("wheel", function (e) {
  e.preventDefault();
  view.dist *= Math.exp(Math.max(-100, Math.min(100, e.deltaY)) * 0.002);
  view.fitted = false; redraw();
}, {passive: false});
canvas.addEventListener("contextmenu", function (e) { e.preventDefault(); });
canvas.addEventListener("dblclick", function () { reset(); redraw(); });
document.getElementById("mbdyn-reset").addEventListener("click", function () { reset(); redraw(); });
function hover(e) {                       // a mount's (or a body's) name under the pointer
  var r = canvas.getBoundingClientRect(), x = e.clientX - r.left, y = e.clientY - r.top;
  var best = null, d2 = 100;
  var names = D.tags.map(function (t) { return t.label; }).concat(D.names);
  drawn.marks.forEach(function (m, n) {
    var s = cam.screen(m.p), d = (s[0] - x) * (s[0] - x) + (s[1] - y) * (s[1] - y);
    if (s[2] > cam.near && d < d2) { d2 = d; best = n; }
  });
  tip.style.visibility = best === null ? "hidden" : "visible";
  if (best !== null) {
    tip.textContent = names[best];
    tip.style.transform = "translate(" + (x + 12) + "px," + (y + 12) + "px)";
  }
}
// ---- controls: play/pause, the slider, its time ticks (as many as fit), the time shown
var slider = document.getElementById("mbdyn-slider"), button = document.getElementById("mbdyn-play");
var clock = document.getElementById("mbdyn-time"), ticks = document.getElementById("mbdyn-ticks");
var times = D.times.map(function (t) { return t / 1000; }), playing = null;
slider.max = String(NT - 1);
function show(k) {
  current = k; slider.value = String(k);
  clock.textContent = "t = " + times[k].toFixed(3) + " s";
  render();
}
function layTicks() {
  var width = slider.getBoundingClientRect().width, span = times[NT - 1] - times[0];
  ticks.textContent = "";
  if (!(span > 0) || width <= 0) return;
  var most = Math.max(1, Math.floor(width / 70)), raw = span / most;
  var step = Math.pow(10, Math.floor(Math.log10(raw)));
  step = [1, 2, 5, 10].map(function (m) { return m * step; }).find(function (s) { return s >= raw; });
  var digits = Math.max(0, -Math.floor(Math.log10(step) + 1e-9));
  for (var t = Math.ceil(times[0] / step) * step; t <= times[NT - 1] + 1e-9; t += step) {
    var e = document.createElement("span");
    e.className = "mbdyn-tick";
    e.textContent = t.toFixed(digits) + " s";
    e.style.left = (8 + (width - 16) * (t - times[0]) / span) + "px";
    ticks.appendChild(e);
  }
}
function stop() {
  if (playing !== null) cancelAnimationFrame(playing);
  playing = null; button.textContent = "play";
}
function play() {
  var start = null, k0 = current >= NT - 1 ? 0 : current;
  button.textContent = "pause";
  function step(now) {
    if (start === null) start = now;
    var k = Math.min(NT - 1, k0 + Math.floor((now - start) / 1000 * D.fps));
    if (k !== current) show(k);
    if (k >= NT - 1) { stop(); return; }
    playing = requestAnimationFrame(step);
  }
  playing = requestAnimationFrame(step);
}
button.addEventListener("click", function () { if (playing === null) play(); else stop(); });
slider.addEventListener("input", function () { stop(); show(Number(slider.value)); });
window.addEventListener("resize", function () { layTicks(); redraw(); });
reset();
show(0);
layTicks();
requestAnimationFrame(function () {       // ready once the first frame is on the screen
  window.mbdynView = {frames: NT, times: times, names: D.names, renderer: renderer.kind,
    goto: function (i) {
      if (!(Number.isInteger(i) && i >= 0 && i < NT)) {
        return Promise.reject(new RangeError("frame " + i + " is not in 0.." + (NT - 1)));
      }
      stop(); show(i); return Promise.resolve();
    },
    positions: function () {               // the centres of mass as drawn (world axes)
      return drawn.marks.slice(D.tags.length).map(function (m) { return m.p.slice(); });
    },
    project: function (p) { return cam.screen(p).slice(0, 2); },
    camera: function () {                  // the pinhole camera drawn with (world axes)
      return {eye: comb(view.target, cam.axes[2], cam.axes[2], view.dist, 0),
        target: view.target.slice(), up: B[2].slice(), fov: FOV,
        width: canvas.clientWidth, height: canvas.clientHeight};
    },
    reset: function () { reset(); render(); }};
});
