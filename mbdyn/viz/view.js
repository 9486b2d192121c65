/* mbdyn's HTML view: rebuilds every frame from the movers' poses (mbdyn/viz/view_data.py)
   and draws it with the plotly.js bundled in the page.  Exposes window.mbdynView:
   frames, times (s), names, goto(i) (a promise), positions() (drawn centres of mass). */
(function () {
  "use strict";
  var D = JSON.parse(document.getElementById("mbdyn-data").textContent);
  var L = JSON.parse(document.getElementById("mbdyn-layout").textContent);
  var gd = document.getElementById("mbdyn-plot");
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
  function at(k, a) {                      // a = [mover, x, y, z] (ints) -> world point
    var x = a[1] * U, y = a[2] * U, z = a[3] * U;
    if (a[0] < 0) return [x, y, z];
    var p = (k * NM + a[0]) * 12, R = pose;
    return [R[p + 9] + R[p] * x + R[p + 1] * y + R[p + 2] * z,
      R[p + 10] + R[p + 3] * x + R[p + 4] * y + R[p + 5] * z,
      R[p + 11] + R[p + 6] * x + R[p + 7] * y + R[p + 8] * z];
  }
  function perp(e) {                       // two unit vectors across the unit vector e
    var h = Math.abs(e[0]) < 0.6 ? [1, 0, 0] : [0, 1, 0];
    var a = [h[1] * e[2] - h[2] * e[1], h[2] * e[0] - h[0] * e[2], h[0] * e[1] - h[1] * e[0]];
    var n = Math.hypot(a[0], a[1], a[2]);
    a = [a[0] / n, a[1] / n, a[2] / n];
    return [a, [e[1] * a[2] - e[2] * a[1], e[2] * a[0] - e[0] * a[2], e[0] * a[1] - e[1] * a[0]]];
  }
  function coil(a, b, radius, out) {       // as viz.drawing.coil
    var d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]], L = Math.hypot(d[0], d[1], d[2]) || 1;
    var q = perp([d[0] / L, d[1] / L, d[2] / L]), n = 96, i, c;
    push(out, a); push(out, lerp(a, b, 0.1));
    for (i = 0; i <= n; i++) {
      var s = i / n, ph = 2 * Math.PI * 8 * s, m = lerp(a, b, 0.1 + 0.8 * s);
      c = [Math.cos(ph) * radius, Math.sin(ph) * radius];
      push(out, [m[0] + c[0] * q[0][0] + c[1] * q[1][0], m[1] + c[0] * q[0][1] + c[1] * q[1][1],
        m[2] + c[0] * q[0][2] + c[1] * q[1][2]]);
    }
    push(out, lerp(a, b, 0.9)); push(out, b); gap(out);
  }
  function lerp(a, b, s) { return [a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1]), a[2] + s * (b[2] - a[2])]; }
  function push(o, p) { o.x.push(p[0]); o.y.push(p[1]); o.z.push(p[2]); }
  function gap(o) { o.x.push(null); o.y.push(null); o.z.push(null); }
  function xyz() { return {x: [], y: [], z: []}; }
  function line(colour, width, name) {
    return {type: "scatter3d", mode: "lines", name: name, hoverinfo: "skip", showlegend: false,
      x: [], y: [], z: [], line: {color: colour, width: width * 2}};
  }
  var lighting = {ambient: 0.45, diffuse: 0.75, specular: 0.15, roughness: 0.6, fresnel: 0.1};
  function mesh(m, colour, opacity) {
    var f = m.f, i = [], j = [], k = [];
    for (var n = 0; n < f.length; n += 3) { i.push(f[n]); j.push(f[n + 1]); k.push(f[n + 2]); }
    return {type: "mesh3d", i: i, j: j, k: k, x: [], y: [], z: [], color: colour,
      opacity: opacity, flatshading: true, lighting: lighting, hoverinfo: "skip",
      showlegend: false, lightposition: {x: 1e5, y: -1e5, z: 1e5}};
  }
  // ---- the traces: solids, planes (static), line groups, coils, dampers, trails, tags, markers
  var traces = [], dynamic = [], builders = [];
  D.solids.forEach(function (s) {
    dynamic.push(traces.length); traces.push(mesh(s, s.color, 1));
    builders.push(function (k) {
      var o = xyz(), v = s.v;
      for (var n = 0; n < v.length; n += 3) push(o, at(k, [s.mover, v[n], v[n + 1], v[n + 2]]));
      return o;
    });
  });
  D.planes.forEach(function (p) {
    var t = mesh(p, p.color, 0.3);
    for (var n = 0; n < p.v.length; n += 3) push(t, [p.v[n] * U, p.v[n + 1] * U, p.v[n + 2] * U]);
    traces.push(t);
  });
  function dynamicLine(trace, build) { dynamic.push(traces.length); traces.push(trace); builders.push(build); }
  D.groups.forEach(function (g) {
    dynamicLine(line(g.color, g.width, "lines"), function (k) {
      var o = xyz();
      g.lines.forEach(function (pts) { pts.forEach(function (a) { push(o, at(k, a)); }); gap(o); });
      return o;
    });
  });
  if (D.springs.length) dynamicLine(line(D.colors.spring, 1.5, "springs"), function (k) {
    var o = xyz();
    D.springs.forEach(function (s) { coil(at(k, s[0]), at(k, s[1]), D.sizes.coil * U, o); });
    return o;
  });
  [[0, 0.55, 7, "damper cylinders"], [0.4, 1, 2.5, "damper rods"]].forEach(function (part) {
    if (D.dampers.length) dynamicLine(line(D.colors.damper, part[2], part[3]), function (k) {
      var o = xyz();
      D.dampers.forEach(function (s) {
        var a = at(k, s[0]), b = at(k, s[1]);
        push(o, lerp(a, b, part[0])); push(o, lerp(a, b, part[1])); gap(o);
      });
      return o;
    });
  });
  var com = [];                           // centres of mass of every frame, then trails
  for (var k = 0; k < NT; k++) com.push(D.markers.map(function (m) { return at(k, m.at); }));
  dynamicLine(line(D.colors.trail, 0.6, "trails"), function (k) {
    var o = xyz(), k0 = Math.max(0, k - D.trail + 1), i, n;
    for (n = 0; n < D.markers.length; n++) {
      for (i = k0; i <= k; i++) push(o, com[i][n]);
      gap(o);
    }
    D.points.forEach(function (p) {
      for (i = k0; i <= k; i++) push(o, [p[3 * i] * U, p[3 * i + 1] * U, p[3 * i + 2] * U]);
      gap(o);
    });
    return o;
  });
  if (D.arrows.length) dynamicLine(line(D.colors.force, 4, "contact forces"), function (k) {
    var o = xyz(), a = D.arrows[k];
    for (var n = 0; n < a.length; n += 6) {
      push(o, [a[n] * U, a[n + 1] * U, a[n + 2] * U]);
      push(o, [a[n + 3] * U, a[n + 4] * U, a[n + 5] * U]); gap(o);
    }
    return o;
  });
  if (D.tags.length) dynamicLine({type: "scatter3d", mode: "markers", name: "mounts",
    showlegend: false, text: D.tags.map(function (t) { return t.label; }),
    hovertemplate: "%{text}<extra></extra>", x: [], y: [], z: [],
    marker: {symbol: "diamond", size: 5, color: D.tags.map(function (t) { return t.color; })}},
  function (k) { var o = xyz(); D.tags.forEach(function (t) { push(o, at(k, t.at)); }); return o; });
  var markerTrace = traces.length;
  dynamicLine({type: "scatter3d", mode: "markers", name: "centres of mass", showlegend: false,
    text: D.labels, hovertemplate: "%{text}<extra></extra>", x: [], y: [], z: [],
    marker: {color: D.markers.map(function (m) { return m.color; }),
      size: D.markers.map(function (m) { return m.size; }), line: {color: "#222", width: 1}}},
  function (k) { var o = xyz(); com[k].forEach(function (p) { push(o, p); }); return o; });
  function fill(k) {
    var x = [], y = [], z = [];
    builders.forEach(function (b) { var o = b(k); x.push(o.x); y.push(o.y); z.push(o.z); });
    return {x: x, y: y, z: z};
  }
  var first = fill(0);
  dynamic.forEach(function (t, n) {
    traces[t].x = first.x[n]; traces[t].y = first.y[n]; traces[t].z = first.z[n];
  });
  // ---- controls: play/pause, the slider, its time ticks (as many as fit), the time shown
  var slider = document.getElementById("mbdyn-slider"), button = document.getElementById("mbdyn-play");
  var clock = document.getElementById("mbdyn-time"), ticks = document.getElementById("mbdyn-ticks");
  var times = D.times.map(function (t) { return t / 1000; }), current = 0, playing = null;
  slider.max = String(NT - 1);
  clock.textContent = "t = " + times[0].toFixed(3) + " s";
  function show(k) {
    current = k; slider.value = String(k);
    clock.textContent = "t = " + times[k].toFixed(3) + " s";
    var f = fill(k);
    return Plotly.restyle(gd, f, dynamic);
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
      var label = document.createElement("span");
      label.className = "mbdyn-tick";
      label.textContent = t.toFixed(digits) + " s";
      label.style.left = (8 + (width - 16) * (t - times[0]) / span) + "px";
      ticks.appendChild(label);
    }
  }
  function stop() {
    if (playing !== null) cancelAnimationFrame(playing);
    playing = null; button.textContent = "play";
  }
  function play() {
    var start = null, k0 = current >= NT - 1 ? 0 : current, busy = false;
    button.textContent = "pause";
    function step(now) {
      if (start === null) start = now;
      var k = Math.min(NT - 1, k0 + Math.floor((now - start) / 1000 * D.fps));
      if (!busy && k !== current) { busy = true; show(k).then(function () { busy = false; }); }
      if (k >= NT - 1) { stop(); return; }
      playing = requestAnimationFrame(step);
    }
    playing = requestAnimationFrame(step);
  }
  button.addEventListener("click", function () { if (playing === null) play(); else stop(); });
  slider.addEventListener("input", function () { stop(); show(Number(slider.value)); });
  window.addEventListener("resize", layTicks);
  Plotly.newPlot(gd, traces, L, {responsive: true, displaylogo: false}).then(function () {
    layTicks();
    window.mbdynView = {frames: NT, times: times, names: D.names,
      goto: function (i) { stop(); return show(i); },
      positions: function () {
        var t = gd.data[markerTrace];
        return t.x.map(function (x, n) { return [x, t.y[n], t.z[n]]; });
      }};
  });
})();
