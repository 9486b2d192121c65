/* The Canvas-2D renderer of mbdyn's HTML view, for a browser without WebGL: the painter's
   algorithm (every triangle and line segment drawn from the farthest to the nearest by the
   depth of its middle), triangles flat-shaded with the same headlight and ambient as the
   WebGL renderer, ground planes translucent, markers last and on top.  Same interface as
   glRenderer: setScene(solids, planes, origin), draw(camera, frame). */
function canvasRenderer(canvas) {
  var ctx = canvas.getContext("2d");
  if (!ctx) return null;
  var solids = [], planes = [];
  function setScene(list, planeList) { solids = list; planes = planeList; }
  function css(rgb, s, alpha) {
    var c = rgb.map(function (x) { return Math.round(255 * Math.min(1, x * s)); });
    return alpha === undefined ? "rgb(" + c.join(",") + ")" : "rgba(" + c.join(",") + "," + alpha + ")";
  }
  function shadeOf(n, L) {                 // |n . L| of a normal n (any length)
    var l = Math.hypot(n[0], n[1], n[2]) || 1;
    return SHADE.ambient + SHADE.diffuse * Math.abs((n[0] * L[0] + n[1] * L[1] + n[2] * L[2]) / l);
  }
  function triangles(items, cam, tri, nrm, pose, rgb, alpha) {
    var w, s = [], i, j, R = pose;
    for (i = 0; i < tri.length; i += 9) {
      var far = 0, ok = true;
      for (j = 0; j < 3; j++) {
        var x = tri[i + 3 * j], y = tri[i + 3 * j + 1], z = tri[i + 3 * j + 2];
        if (R) {
          w = [R[9] + R[0] * x + R[1] * y + R[2] * z, R[10] + R[3] * x + R[4] * y + R[5] * z,
            R[11] + R[6] * x + R[7] * y + R[8] * z];
        } else w = [x, y, z];
        s[j] = cam.screen(w);
        if (s[j][2] <= cam.near) ok = false;
        far += s[j][2];
      }
      if (!ok) continue;
      var n = [nrm[i], nrm[i + 1], nrm[i + 2]];
      if (R) n = [R[0] * n[0] + R[1] * n[1] + R[2] * n[2], R[3] * n[0] + R[4] * n[1] + R[5] * n[2],
        R[6] * n[0] + R[7] * n[1] + R[8] * n[2]];
      items.push({z: far / 3, tri: [s[0], s[1], s[2]], fill: css(rgb, shadeOf(n, cam.light), alpha)});
    }
  }
  function draw(cam, frame) {
    var items = [], dpr = cam.dpr;
    solids.forEach(function (s) {
      var b = s.mover * 12;
      triangles(items, cam, s.tri, s.nrm, frame.poses.subarray(b, b + 12), s.rgb);
    });
    planes.forEach(function (p) { triangles(items, cam, p.tri, p.nrm, null, p.rgb, PLANE_ALPHA); });
    frame.lines.forEach(function (l) {
      var stroke = css(l.rgb, 1), p = l.pts;
      for (var i = 0; i < p.length; i += 6) {
        var a = cam.screen([p[i], p[i + 1], p[i + 2]]), e = cam.screen([p[i + 3], p[i + 4], p[i + 5]]);
        if (a[2] <= cam.near || e[2] <= cam.near) continue;
        items.push({z: (a[2] + e[2]) / 2, seg: [a, e], stroke: stroke, width: l.width});
      }
    });
    items.sort(function (p, q) { return q.z - p.z; });
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    ctx.fillStyle = "#ffffff";
    ctx.fillRect(0, 0, canvas.width / dpr, canvas.height / dpr);
    ctx.lineJoin = "round"; ctx.lineCap = "round";
    items.forEach(function (it) {
      ctx.beginPath();
      if (it.tri) {
        var t = it.tri;
        ctx.moveTo(t[0][0], t[0][1]); ctx.lineTo(t[1][0], t[1][1]); ctx.lineTo(t[2][0], t[2][1]);
        ctx.closePath();
        ctx.fillStyle = it.fill; ctx.fill();
        if (it.fill.charAt(3) !== "a") {    // opaque: close the hairline seams between faces
          ctx.strokeStyle = it.fill; ctx.lineWidth = 0.6; ctx.stroke();
        }
      } else {
        ctx.moveTo(it.seg[0][0], it.seg[0][1]); ctx.lineTo(it.seg[1][0], it.seg[1][1]);
        ctx.strokeStyle = it.stroke; ctx.lineWidth = it.width; ctx.stroke();
      }
    });
    frame.marks.forEach(function (m) {
      var s = cam.screen(m.p), r = m.size / 2;
      if (s[2] <= cam.near) return;
      ctx.beginPath();
      if (m.shape < 0.5) ctx.arc(s[0], s[1], r, 0, 2 * Math.PI);
      else {
        ctx.moveTo(s[0], s[1] - r); ctx.lineTo(s[0] + r, s[1]);
        ctx.lineTo(s[0], s[1] + r); ctx.lineTo(s[0] - r, s[1]); ctx.closePath();
      }
      ctx.fillStyle = css(m.rgb, 1); ctx.fill();
      if (m.shape < 0.5) { ctx.strokeStyle = "#212121"; ctx.lineWidth = 1; ctx.stroke(); }
    });
  }
  return {kind: "2d", setScene: setScene, draw: draw};
}
