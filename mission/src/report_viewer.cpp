#include "report_viewer.hpp"

#include <fstream>
#include <sstream>

#include "html_report.hpp"

#ifndef PITCHLAB_THREE_JS_DIR
#define PITCHLAB_THREE_JS_DIR ""
#endif

namespace pitchlab::mission {
namespace {

Result<std::string> Slurp(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    return Fail(Error::Code::kNotFound,
                file.string() + ": not found (install Debian's libjs-three)");
  }
  std::ostringstream s;
  s << in.rdbuf();
  // Inlined into a <script> element, which the HTML parser ends at the first "</script".
  if (s.str().find("</script") != std::string::npos) {
    return Fail(Error::Code::kFailed, file.string() + ": contains \"</script\", cannot inline");
  }
  return s.str();
}

// The viewer. Plain ES5 (three.js r111's own level) so any browser that runs three.js runs it.
constexpr const char* kViewerJs = R"JS(
(function () {
  'use strict';
  var root = document.getElementById('view3d');
  var message = root.querySelector('.view3d-msg');
  function fail(why) {
    root.setAttribute('data-status', 'error');
    message.textContent = '3D view unavailable: ' + why;
    message.hidden = false;
  }
  function bytes(b64) {
    var s = atob(b64), u = new Uint8Array(s.length);
    for (var i = 0; i < s.length; ++i) u[i] = s.charCodeAt(i);
    return u;
  }
  function int16(b64) {  // little-endian, as report_scene.cpp writes them
    var u = bytes(b64), v = new DataView(u.buffer), out = new Int32Array(u.length >> 1);
    for (var i = 0; i < out.length; ++i) out[i] = v.getInt16(2 * i, true);
    return out;
  }
  function cloud(c, box) {
    var q = int16(c.xyz), n = q.length / 3;
    var pos = new Float32Array(q.length), col = new Float32Array(q.length);
    var lo = Infinity, hi = -Infinity;
    for (var i = 0; i < q.length; ++i) pos[i] = c.origin[i % 3] + (q[i] + 32767) * c.scale;
    for (i = 0; i < n; ++i) { lo = Math.min(lo, pos[3 * i + 2]); hi = Math.max(hi, pos[3 * i + 2]); }
    for (i = 0; i < n; ++i) {  // dark slate low to pale grey high: reads as depth, not as a hazard
      var t = hi > lo ? (pos[3 * i + 2] - lo) / (hi - lo) : 0.5;
      col[3 * i] = 0.2 + 0.6 * t; col[3 * i + 1] = 0.25 + 0.55 * t; col[3 * i + 2] = 0.4 + 0.45 * t;
    }
    var g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(pos, 3));
    g.setAttribute('color', new THREE.BufferAttribute(col, 3));
    g.computeBoundingBox();
    if (n > 0) box.union(g.boundingBox);
    return new THREE.Points(g, new THREE.PointsMaterial(
        {size: 1.5, sizeAttenuation: false, vertexColors: THREE.VertexColors}));
  }
  function surface(s, box) {
    var z = int16(s.z), rgb = bytes(s.rgb), n = s.nx * s.ny;
    var pos = new Float32Array(3 * n), col = new Float32Array(3 * n), index = [];
    for (var j = 0; j < s.ny; ++j) {
      for (var i = 0; i < s.nx; ++i) {
        var k = j * s.nx + i, known = z[k] !== -32768;
        pos[3 * k] = s.x0 + (i + 0.5) * s.cell;
        pos[3 * k + 1] = s.y0 + (j + 0.5) * s.cell;
        pos[3 * k + 2] = known ? s.z0 + (z[k] + 32767) * s.scale : 0;
        for (var a = 0; a < 3; ++a) col[3 * k + a] = rgb[3 * k + a] / 255;
        if (known) box.expandByPoint(new THREE.Vector3(pos[3 * k], pos[3 * k + 1], pos[3 * k + 2]));
        // Two triangles per square of four known cell centres; holes stay holes.
        if (i + 1 < s.nx && j + 1 < s.ny && known && z[k + 1] !== -32768 &&
            z[k + s.nx] !== -32768 && z[k + s.nx + 1] !== -32768) {
          index.push(k, k + 1, k + s.nx + 1, k, k + s.nx + 1, k + s.nx);
        }
      }
    }
    var g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(pos, 3));
    g.setAttribute('color', new THREE.BufferAttribute(col, 3));
    g.setIndex(new THREE.BufferAttribute(n > 65535 ? new Uint32Array(index) : new Uint16Array(index), 1));
    g.computeVertexNormals();
    // Pulled towards the camera in depth: the cloud's ground points (on the surface, within the
    // range noise) hide behind it, points above the ground (walls, rocks) stay in view.
    return new THREE.Mesh(g, new THREE.MeshLambertMaterial({
      vertexColors: THREE.VertexColors, side: THREE.DoubleSide,
      polygonOffset: true, polygonOffsetFactor: -4, polygonOffsetUnits: -4}));
  }
  // A tube, not a GL line: WebGL draws lines 1 px wide whatever their width says.
  function path(points, colour, radius, box) {
    var v = [];
    for (var i = 0; i < points.length; ++i) {
      v.push(new THREE.Vector3(points[i][0], points[i][1], points[i][2]));
      box.expandByPoint(v[i]);
    }
    if (v.length < 2) return new THREE.Group();
    var g = new THREE.TubeBufferGeometry(new THREE.CatmullRomCurve3(v), 2 * v.length, radius, 6, false);
    // Further forward in depth than the surface: a path on the ground stays visible.
    return new THREE.Mesh(g, new THREE.MeshLambertMaterial(
        {color: colour, polygonOffset: true, polygonOffsetFactor: -8, polygonOffsetUnits: -8}));
  }
  function ball(p, radius, colour) {
    var m = new THREE.Mesh(new THREE.SphereBufferGeometry(radius, 16, 12),
                           new THREE.MeshLambertMaterial({color: colour, polygonOffset: true,
                                                          polygonOffsetFactor: -8,
                                                          polygonOffsetUnits: -8}));
    m.position.set(p[0], p[1], p[2]);
    return m;
  }
  function drawnPixels(renderer, background) {
    var gl = renderer.getContext(), w = gl.drawingBufferWidth, h = gl.drawingBufferHeight;
    var px = new Uint8Array(4 * w * h), drawn = 0;
    gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, px);
    for (var i = 0; i < w * h; ++i) {
      if (Math.abs(px[4 * i] - background[0]) + Math.abs(px[4 * i + 1] - background[1]) +
          Math.abs(px[4 * i + 2] - background[2]) > 12) ++drawn;
    }
    return drawn;
  }
  function main() {
    if (typeof THREE === 'undefined' || !THREE.OrbitControls) throw new Error('three.js did not load');
    var probe = document.createElement('canvas');
    if (!(probe.getContext('webgl') || probe.getContext('experimental-webgl'))) {
      throw new Error('this browser offers no WebGL');
    }
    var d = JSON.parse(document.getElementById('scene-data').textContent);
    var holder = root.querySelector('.view3d-canvas');
    var renderer = new THREE.WebGLRenderer({antialias: true, preserveDrawingBuffer: true});
    renderer.setPixelRatio(window.devicePixelRatio || 1);
    holder.appendChild(renderer.domElement);
    var scene = new THREE.Scene();
    var background = [244, 244, 244];
    scene.background = new THREE.Color(background[0] / 255, background[1] / 255, background[2] / 255);
    scene.add(new THREE.AmbientLight(0xffffff, 0.6));
    var sun = new THREE.DirectionalLight(0xffffff, 0.5);
    sun.position.set(-1, 1, 2);  // from the north-west, as the map pictures' hillshade
    scene.add(sun);
    // The view frames the mapped surface and the trajectories; the cloud only when there is
    // nothing else (its far returns would shrink the scene to a speck).
    var box = new THREE.Box3(), cloudBox = new THREE.Box3(), layers = {};
    layers.surface = surface(d.surface, box);
    layers.cloud = cloud(d.cloud, cloudBox);
    if (box.isEmpty()) box.copy(cloudBox);
    // Thick enough to see from the whole scene's view, thin beside the robot (0.5 m wide).
    var radius = Math.max(0.03, box.getSize(new THREE.Vector3()).length() / 600);
    layers.paths = new THREE.Group();
    layers.paths.add(path(d['true'], 0x1e50ff, radius, box), path(d.estimated, 0xe08000, radius, box));
    layers.stops = new THREE.Group();
    for (var i = 0; i < d.stops.length; ++i) layers.stops.add(ball(d.stops[i], 0.12, 0x20a020));
    layers.stops.add(ball(d.start, 0.25, 0x111111), ball(d.goal, 0.25, 0xd01010));
    for (var name in layers) scene.add(layers[name]);
    if (box.isEmpty()) box.set(new THREE.Vector3(-1, -1, -1), new THREE.Vector3(1, 1, 1));
    var centre = box.getCenter(new THREE.Vector3()), size = box.getSize(new THREE.Vector3()).length();
    var camera = new THREE.PerspectiveCamera(45, 1, size / 1000, size * 10);
    camera.up.set(0, 0, 1);  // REP-103: z up
    var controls = new THREE.OrbitControls(camera, renderer.domElement);
    controls.screenSpacePanning = true;
    function render() { renderer.render(scene, camera); }
    function view(from) {
      camera.position.copy(centre).add(from.normalize().multiplyScalar(0.7 * size));
      controls.target.copy(centre);
      controls.update();
      render();
    }
    function resize() {
      var w = holder.clientWidth, h = Math.round(Math.min(640, Math.max(360, 0.55 * w)));
      renderer.setSize(w, h);
      camera.aspect = w / h;
      camera.updateProjectionMatrix();
      render();
    }
    controls.addEventListener('change', render);
    window.addEventListener('resize', resize);
    root.querySelector('.view3d-reset').onclick = function () { view(new THREE.Vector3(-0.45, -0.6, 0.55)); };
    root.querySelector('.view3d-top').onclick = function () { view(new THREE.Vector3(0, -0.001, 1.0)); };
    var toggles = root.querySelectorAll('input[data-layer]');
    for (i = 0; i < toggles.length; ++i) {
      toggles[i].onchange = function () { layers[this.getAttribute('data-layer')].visible = this.checked; render(); };
    }
    resize();
    view(new THREE.Vector3(-0.45, -0.6, 0.55));
    root.setAttribute('data-drawn-pixels', String(drawnPixels(renderer, background)));
    root.setAttribute('data-status', 'ok');
  }
  try { main(); } catch (e) { fail(e.message); console.error('3D view: ' + e.message); }
})();
)JS";

}  // namespace

std::filesystem::path DefaultThreeJsDir() { return PITCHLAB_THREE_JS_DIR; }

Result<ThreeJs> LoadThreeJs(const std::filesystem::path& dir) {
  if (dir.empty()) {
    return Fail(Error::Code::kNotFound,
                "three.js was not found when pitchlab was built (install Debian's libjs-three and "
                "re-run cmake)");
  }
  Result<std::string> three = Slurp(dir / "three.min.js");
  if (!three) return tl::unexpected(three.error());
  Result<std::string> orbit = Slurp(dir / "examples/js/controls/OrbitControls.js");
  if (!orbit) return tl::unexpected(orbit.error());
  return ThreeJs{std::move(*three), std::move(*orbit)};
}

std::string ViewerHtml(const std::string& scene_json, const ThreeJs& three) {
  return "<div id=view3d data-status=loading>\n"
         "<div class=view3d-bar><button class=view3d-reset type=button>reset view</button> "
         "<button class=view3d-top type=button>top view</button> "
         "<label><input type=checkbox data-layer=surface checked> surface</label> "
         "<label><input type=checkbox data-layer=cloud checked> cloud</label> "
         "<label><input type=checkbox data-layer=paths checked> trajectories</label> "
         "<label><input type=checkbox data-layer=stops checked> stops</label> "
         "<span class=hint>drag: orbit, wheel: zoom, right drag: pan</span></div>\n"
         "<p class=view3d-msg hidden></p><div class=view3d-canvas></div>\n"
         "<script type=application/json id=scene-data>" +
         scene_json + "</script>\n<script>" + three.three + "\n</script>\n<script>" +
         three.orbit_controls + "\n</script>\n<script>" + kViewerJs + "</script>\n</div>\n";
}

std::string ViewerUnavailableHtml(const std::string& why) {
  return "<div id=view3d data-status=unavailable><p class=note>The 3D view is unavailable: " +
         HtmlEscape(why) + "</p></div>\n";
}

}  // namespace pitchlab::mission
