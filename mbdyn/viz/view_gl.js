/* The WebGL renderer of mbdyn's HTML view (view.js drives it; view_2d.js is the fallback).
   Solids: flat-shaded triangles, sent once in their mover's axes and posed by a model matrix
   per draw, lit by a headlight (Lambert, both sides) plus ambient, with a depth buffer;
   translucent ground planes after them without writing depth; lines as screen-space quads
   of their width in CSS pixels (depth-tested); markers last, on top (circles with an
   outline, diamonds).  Coordinates reach the GPU relative to the scene's origin O (floats
   near zero).  glRenderer(canvas) is null when the browser gives no WebGL. */
var GL_SHADERS = {
  meshV: "attribute vec3 p; attribute vec3 n; uniform mat4 VP; uniform mat4 M;" +
    " uniform mat3 R; uniform vec3 L; varying float s;" +
    " void main() { gl_Position = VP * M * vec4(p, 1.0);" +
    "   s = AMBIENT + DIFFUSE * abs(dot(normalize(R * n), L)); }",
  meshF: "precision mediump float; uniform vec4 c; varying float s;" +
    " void main() { gl_FragColor = vec4(min(c.rgb * s, vec3(1.0)), c.a); }",
  lineV: "attribute vec3 a; attribute vec3 b; attribute vec2 k; uniform mat4 VP;" +
    " uniform vec2 px; uniform float w;" +
    " void main() { vec4 ha = VP * vec4(a, 1.0), hb = VP * vec4(b, 1.0);" +
    "   if (ha.w <= 0.0 || hb.w <= 0.0) { gl_Position = vec4(2.0, 2.0, 2.0, 1.0); return; }" +
    "   vec2 d = (hb.xy / hb.w - ha.xy / ha.w) * px; float l = length(d);" +
    "   d = l > 0.0 ? d / l : vec2(1.0, 0.0);" +
    "   vec4 h = k.x < 0.5 ? ha : hb;" +
    "   vec2 off = (vec2(-d.y, d.x) * k.y + d * (2.0 * k.x - 1.0)) * 2.0 * w / px;" +
    "   gl_Position = vec4(h.xy + off * h.w, h.zw); }",
  lineF: "precision mediump float; uniform vec3 c; void main() { gl_FragColor = vec4(c, 1.0); }",
  markV: "attribute vec3 p; attribute vec2 k; attribute vec3 c; attribute vec2 z;" +
    " uniform mat4 VP; uniform vec2 px; varying vec2 q; varying vec3 col; varying vec2 sh;" +
    " void main() { vec4 h = VP * vec4(p, 1.0);" +
    "   if (h.w <= 0.0) { gl_Position = vec4(2.0, 2.0, 2.0, 1.0); return; }" +
    "   gl_Position = vec4(h.xy + k * z.x / px * h.w, 0.0, h.w);" +
    "   q = k; col = c; sh = vec2(z.y, 2.0 / max(z.x, 1.0)); }",
  markF: "precision mediump float; varying vec2 q; varying vec3 col; varying vec2 sh;" +
    " void main() { float d = sh.x < 0.5 ? length(q) : abs(q.x) + abs(q.y);" +
    "   if (d > 1.0) discard;" +
    "   gl_FragColor = vec4(sh.x < 0.5 && d > 1.0 - sh.y ? vec3(0.13) : col, 1.0); }"
};

function glRenderer(canvas) {
  var gl = null;
  try {
    gl = canvas.getContext("webgl", {antialias: true, alpha: false, preserveDrawingBuffer: true});
  } catch (e) { gl = null; }
  if (!gl) return null;
  function compile(vs, fs) {
    var prog = gl.createProgram();
    [[gl.VERTEX_SHADER, vs], [gl.FRAGMENT_SHADER, fs]].forEach(function (s) {
      var sh = gl.createShader(s[0]);
      gl.shaderSource(sh, s[1].replace("AMBIENT", SHADE.ambient.toFixed(3))
        .replace("DIFFUSE", SHADE.diffuse.toFixed(3)));
      gl.compileShader(sh);
      if (!gl.getShaderParameter(sh, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(sh));
      gl.attachShader(prog, sh);
    });
    gl.linkProgram(prog);
    if (!gl.getProgramParameter(prog, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(prog));
    var loc = {prog: prog}, i, n = gl.getProgramParameter(prog, gl.ACTIVE_ATTRIBUTES);
    for (i = 0; i < n; i++) {
      var a = gl.getActiveAttrib(prog, i).name;
      loc[a] = gl.getAttribLocation(prog, a);
    }
    n = gl.getProgramParameter(prog, gl.ACTIVE_UNIFORMS);
    for (i = 0; i < n; i++) {
      var u = gl.getActiveUniform(prog, i).name;
      loc[u] = gl.getUniformLocation(prog, u);
    }
    return loc;
  }
  var mesh, line, mark;
  try {
    mesh = compile(GL_SHADERS.meshV, GL_SHADERS.meshF);
    line = compile(GL_SHADERS.lineV, GL_SHADERS.lineF);
    mark = compile(GL_SHADERS.markV, GL_SHADERS.markF);
  } catch (e) { return null; }           // a WebGL that cannot run these: the 2D fallback
  var solidBuf = gl.createBuffer(), planeBuf = gl.createBuffer(), lineBuf = gl.createBuffer(),
    markBuf = gl.createBuffer(), solids = [], planes = [], origin = [0, 0, 0];
  function attrib(loc, name, size, stride, offset) {
    if (loc[name] === undefined || loc[name] < 0) return;
    gl.enableVertexAttribArray(loc[name]);
    gl.vertexAttribPointer(loc[name], size, gl.FLOAT, false, stride * 4, offset * 4);
  }
  function detach(loc) {
    for (var key in loc) {
      if (typeof loc[key] === "number" && loc[key] >= 0) gl.disableVertexAttribArray(loc[key]);
    }
  }
  // static geometry: each solid as triangles (position, face normal) in its mover's axes
  function setScene(list, planeList, o) {
    origin = o;
    var total = 0, off = 0;
    list.forEach(function (s) { total += s.tri.length; });
    var data = new Float32Array(total * 2);
    solids = list.map(function (s) {
      var first = off / 6;
      for (var i = 0; i < s.tri.length; i += 3) {
        data.set([s.tri[i], s.tri[i + 1], s.tri[i + 2], s.nrm[i], s.nrm[i + 1], s.nrm[i + 2]], off);
        off += 6;
      }
      return {mover: s.mover, first: first, count: s.tri.length / 3, rgb: s.rgb};
    });
    gl.bindBuffer(gl.ARRAY_BUFFER, solidBuf);
    gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW);
    var pd = [];
    planes = planeList.map(function (p) {
      var first = pd.length / 6;
      for (var i = 0; i < p.tri.length; i += 3) {
        pd.push(p.tri[i] - o[0], p.tri[i + 1] - o[1], p.tri[i + 2] - o[2],
          p.nrm[i], p.nrm[i + 1], p.nrm[i + 2]);
      }
      return {first: first, count: p.tri.length / 3, rgb: p.rgb};
    });
    gl.bindBuffer(gl.ARRAY_BUFFER, planeBuf);
    gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(pd), gl.STATIC_DRAW);
  }
  var IDENTITY4 = new Float32Array([1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]);
  var IDENTITY3 = new Float32Array([1, 0, 0, 0, 1, 0, 0, 0, 1]);
  function drawMeshes(cam, poses) {
    gl.useProgram(mesh.prog);
    gl.uniformMatrix4fv(mesh.VP, false, cam.vp);
    gl.uniform3fv(mesh.L, cam.light);
    gl.bindBuffer(gl.ARRAY_BUFFER, solidBuf);
    attrib(mesh, "p", 3, 6, 0); attrib(mesh, "n", 3, 6, 3);
    var M = new Float32Array(16), R = new Float32Array(9);
    solids.forEach(function (s) {
      var P = poses, b = s.mover * 12;      // R row-major (9), r (3)
      for (var i = 0; i < 3; i++) {
        for (var j = 0; j < 3; j++) { M[4 * j + i] = P[b + 3 * i + j]; R[3 * j + i] = P[b + 3 * i + j]; }
        M[12 + i] = P[b + 9 + i] - origin[i];
      }
      M[15] = 1;
      gl.uniformMatrix4fv(mesh.M, false, M); gl.uniformMatrix3fv(mesh.R, false, R);
      gl.uniform4f(mesh.c, s.rgb[0], s.rgb[1], s.rgb[2], 1);
      gl.drawArrays(gl.TRIANGLES, s.first, s.count);
    });
    if (planes.length) {                   // translucent, after the opaque, depth kept
      gl.bindBuffer(gl.ARRAY_BUFFER, planeBuf);
      attrib(mesh, "p", 3, 6, 0); attrib(mesh, "n", 3, 6, 3);
      gl.uniformMatrix4fv(mesh.M, false, IDENTITY4); gl.uniformMatrix3fv(mesh.R, false, IDENTITY3);
      gl.enable(gl.BLEND); gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA); gl.depthMask(false);
      planes.forEach(function (p) {
        gl.uniform4f(mesh.c, p.rgb[0], p.rgb[1], p.rgb[2], PLANE_ALPHA);
        gl.drawArrays(gl.TRIANGLES, p.first, p.count);
      });
      gl.disable(gl.BLEND); gl.depthMask(true);
    }
    detach(mesh);
  }
  function drawLines(cam, lines) {
    var n = 0;
    lines.forEach(function (l) { n += l.pts.length / 6; });
    if (!n) return;
    var data = new Float32Array(n * 48), off = 0, o = origin, ranges = [];
    var K = [0, -1, 0, 1, 1, 1, 0, -1, 1, 1, 1, -1];
    lines.forEach(function (l) {
      var first = off / 8, p = l.pts;
      for (var i = 0; i < p.length; i += 6) {
        for (var v = 0; v < 6; v++) {
          data[off++] = p[i] - o[0]; data[off++] = p[i + 1] - o[1]; data[off++] = p[i + 2] - o[2];
          data[off++] = p[i + 3] - o[0]; data[off++] = p[i + 4] - o[1]; data[off++] = p[i + 5] - o[2];
          data[off++] = K[2 * v]; data[off++] = K[2 * v + 1];
        }
      }
      ranges.push([first, off / 8 - first, l.rgb, l.width]);
    });
    gl.useProgram(line.prog);
    gl.uniformMatrix4fv(line.VP, false, cam.vp);
    gl.uniform2f(line.px, cam.width, cam.height);
    gl.bindBuffer(gl.ARRAY_BUFFER, lineBuf);
    gl.bufferData(gl.ARRAY_BUFFER, data, gl.STREAM_DRAW);
    attrib(line, "a", 3, 8, 0); attrib(line, "b", 3, 8, 3); attrib(line, "k", 2, 8, 6);
    ranges.forEach(function (r) {
      gl.uniform3fv(line.c, r[2]); gl.uniform1f(line.w, r[3] * cam.dpr / 2);
      gl.drawArrays(gl.TRIANGLES, r[0], r[1]);
    });
    detach(line);
  }
  function drawMarks(cam, marks) {
    if (!marks.length) return;
    var data = new Float32Array(marks.length * 60), off = 0, o = origin;
    var K = [-1, -1, 1, -1, 1, 1, -1, -1, 1, 1, -1, 1];
    marks.forEach(function (m) {
      for (var v = 0; v < 6; v++) {
        data.set([m.p[0] - o[0], m.p[1] - o[1], m.p[2] - o[2], K[2 * v], K[2 * v + 1],
          m.rgb[0], m.rgb[1], m.rgb[2], m.size * cam.dpr, m.shape], off);
        off += 10;
      }
    });
    gl.useProgram(mark.prog);
    gl.uniformMatrix4fv(mark.VP, false, cam.vp);
    gl.uniform2f(mark.px, cam.width, cam.height);
    gl.bindBuffer(gl.ARRAY_BUFFER, markBuf);
    gl.bufferData(gl.ARRAY_BUFFER, data, gl.STREAM_DRAW);
    attrib(mark, "p", 3, 10, 0); attrib(mark, "k", 2, 10, 3); attrib(mark, "c", 3, 10, 5);
    attrib(mark, "z", 2, 10, 8);
    gl.disable(gl.DEPTH_TEST);
    gl.drawArrays(gl.TRIANGLES, 0, marks.length * 6);
    gl.enable(gl.DEPTH_TEST);
    detach(mark);
  }
  function draw(cam, frame) {
    gl.viewport(0, 0, canvas.width, canvas.height);
    gl.clearColor(1, 1, 1, 1);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    gl.enable(gl.DEPTH_TEST); gl.depthFunc(gl.LEQUAL);
    drawMeshes(cam, frame.poses);
    drawLines(cam, frame.lines);
    drawMarks(cam, frame.marks);
  }
  return {kind: "webgl", setScene: setScene, draw: draw};
}
