// Embree caster. Scene layout:
//  - static scene (RTC_BUILD_QUALITY_HIGH): every geom welded to the world, in world coordinates:
//    one triangle geometry for all boxes, meshes and heightfields, one user geometry for all
//    planes and quadrics (exact analytic tests, primitive i = static_shapes_[i]);
//  - one sub-scene per moving geom (body with a joint, or mocap), in the geom's own frame, placed
//    by an instance whose transform Refresh() sets from geom_xpos / geom_xmat;
//  - top scene: the static scene as an identity instance plus the moving instances, rebuilt in
//    Refresh() (a handful of instances, cheap). Without moving geoms the rays go straight into the
//    static scene, one instancing level less.
// Rays are traced in coherent packets of 16 (8 on CPUs without native 16-wide support).

#include <embree3/rtcore.h>
#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "geom_shapes.hpp"
#include "pitchlab/sensors/ray_caster.hpp"
#include "ray_caster_common.hpp"

namespace pitchlab::sensors {
namespace {

using detail::AnalyticShape;
using detail::TriangleSoup;

// Sentinel in geom maps: "the hit's primID is already the MuJoCo geom id" (user geometry).
constexpr int kGeomIsPrimId = -2;

// Owns an Embree device and the message of its last error. Embree reports errors through a
// callback (registered at device creation, as in tutorials/minimal); throwing through Embree's C
// frames is undefined, so the callback records and Check() throws after each API step.
class Device {
 public:
  Device() {
    device_ = rtcNewDevice(nullptr);
    if (device_ == nullptr) {
      throw std::runtime_error("Embree ray caster: rtcNewDevice failed: " +
                               std::to_string(rtcGetDeviceError(nullptr)));
    }
    rtcSetDeviceErrorFunction(device_, &Device::OnError, this);
  }
  ~Device() { rtcReleaseDevice(device_); }
  Device(const Device&) = delete;
  Device& operator=(const Device&) = delete;

  RTCDevice get() const { return device_; }

  /// Throws std::runtime_error naming `step` and Embree's message when an error was reported.
  void Check(const char* step) {
    const RTCError code = rtcGetDeviceError(device_);
    if (error_.empty() && code == RTC_ERROR_NONE) return;
    const std::string message = error_.empty() ? "error code " + std::to_string(code) : error_;
    error_.clear();
    throw std::runtime_error(std::string("Embree ray caster: ") + step + ": " + message);
  }

 private:
  static void OnError(void* user, RTCError code, const char* text) {
    auto* self = static_cast<Device*>(user);
    if (self->error_.empty()) {
      self->error_ =
          std::string(text != nullptr ? text : "") + " (code " + std::to_string(code) + ")";
    }
  }

  RTCDevice device_ = nullptr;
  std::string error_;
};

// Embree callbacks of the user geometry: `geometryUserPtr` points at an array of shapes.
void ShapeBoundsCallback(const RTCBoundsFunctionArguments* args) {
  const auto* shapes = static_cast<const AnalyticShape*>(args->geometryUserPtr);
  float lower[3], upper[3];
  detail::ShapeBounds(shapes[args->primID], lower, upper);
  RTCBounds* b = args->bounds_o;
  b->lower_x = lower[0];
  b->lower_y = lower[1];
  b->lower_z = lower[2];
  b->upper_x = upper[0];
  b->upper_y = upper[1];
  b->upper_z = upper[2];
}

void ShapeIntersectCallback(const RTCIntersectFunctionNArguments* args) {
  const auto& shape = static_cast<const AnalyticShape*>(args->geometryUserPtr)[args->primID];
  const unsigned n = args->N;
  RTCRayN* ray = RTCRayHitN_RayN(args->rayhit, n);
  RTCHitN* hit = RTCRayHitN_HitN(args->rayhit, n);
  for (unsigned i = 0; i < n; ++i) {
    if (args->valid[i] != -1) continue;
    const double org[3] = {RTCRayN_org_x(ray, n, i), RTCRayN_org_y(ray, n, i),
                           RTCRayN_org_z(ray, n, i)};
    const double dir[3] = {RTCRayN_dir_x(ray, n, i), RTCRayN_dir_y(ray, n, i),
                           RTCRayN_dir_z(ray, n, i)};
    const double t =
        detail::IntersectShape(shape, org, dir, RTCRayN_tnear(ray, n, i), RTCRayN_tfar(ray, n, i));
    if (t < 0.0) continue;
    RTCRayN_tfar(ray, n, i) = static_cast<float>(t);
    RTCHitN_Ng_x(hit, n, i) = 0.0f;  // normals are not part of the contract
    RTCHitN_Ng_y(hit, n, i) = 0.0f;
    RTCHitN_Ng_z(hit, n, i) = 1.0f;
    RTCHitN_u(hit, n, i) = 0.0f;
    RTCHitN_v(hit, n, i) = 0.0f;
    RTCHitN_primID(hit, n, i) = static_cast<unsigned>(shape.geom);
    RTCHitN_geomID(hit, n, i) = args->geomID;
    RTCHitN_instID(hit, n, i, 0) = args->context->instID[0];
  }
}

// Attaches `shapes` (must outlive the scene) as one user geometry; returns its geometry id.
unsigned AttachShapes(Device& device, RTCScene scene, const AnalyticShape* shapes,
                      std::size_t count) {
  RTCGeometry geometry = rtcNewGeometry(device.get(), RTC_GEOMETRY_TYPE_USER);
  rtcSetGeometryUserPrimitiveCount(geometry, static_cast<unsigned>(count));
  rtcSetGeometryUserData(geometry, const_cast<AnalyticShape*>(shapes));
  rtcSetGeometryBoundsFunction(geometry, &ShapeBoundsCallback, nullptr);
  rtcSetGeometryIntersectFunction(geometry, &ShapeIntersectCallback);
  rtcCommitGeometry(geometry);
  const unsigned id = rtcAttachGeometry(scene, geometry);
  rtcReleaseGeometry(geometry);
  device.Check("attaching analytic shapes");
  return id;
}

// Attaches the soup as one triangle geometry; returns its geometry id.
unsigned AttachTriangles(Device& device, RTCScene scene, const TriangleSoup& soup) {
  RTCGeometry geometry = rtcNewGeometry(device.get(), RTC_GEOMETRY_TYPE_TRIANGLE);
  const std::size_t vertex_count = soup.vertices.size() / 3;
  const std::size_t triangle_count = soup.indices.size() / 3;
  auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(
      geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), vertex_count));
  auto* indices = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
      geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), triangle_count));
  device.Check("allocating triangle buffers");
  std::memcpy(vertices, soup.vertices.data(), soup.vertices.size() * sizeof(float));
  std::memcpy(indices, soup.indices.data(), soup.indices.size() * sizeof(unsigned));
  rtcCommitGeometry(geometry);
  const unsigned id = rtcAttachGeometry(scene, geometry);
  rtcReleaseGeometry(geometry);
  device.Check("attaching triangles");
  return id;
}

// Shape of geom g posed by (pos, mat) in its parent frame.
AnalyticShape MakeShape(const mjModel* m, int g, const double pos[3], const double mat[9]) {
  AnalyticShape shape;
  shape.type = m->geom_type[g];
  shape.geom = g;
  std::copy(m->geom_size + 3 * g, m->geom_size + 3 * g + 3, shape.size);
  std::copy(pos, pos + 3, shape.pos);
  std::copy(mat, mat + 9, shape.mat);
  return shape;
}

// Embree's 3x4 column-major transform from MuJoCo's position and row-major rotation.
void ToEmbreeTransform(const mjtNum* pos, const mjtNum* mat, float xfm[12]) {
  for (int col = 0; col < 3; ++col) {
    for (int row = 0; row < 3; ++row) xfm[3 * col + row] = static_cast<float>(mat[3 * row + col]);
  }
  for (int i = 0; i < 3; ++i) xfm[9 + i] = static_cast<float>(pos[i]);
}

RTCScene NewScene(Device& device, RTCBuildQuality quality) {
  RTCScene scene = rtcNewScene(device.get());
  rtcSetSceneBuildQuality(scene, quality);
  // Watertight triangles: a ray through a shared edge or vertex (a vertical truth ray over a
  // heightfield vertex, a beam grazing a box edge) may not slip through; costs ~5 % here.
  rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
  device.Check("creating a scene");
  return scene;
}

// A geom on a moving body: its own scene in the geom frame, instanced into the top scene.
struct MovingGeom {
  int geom = -1;
  RTCScene scene = nullptr;
  RTCGeometry instance = nullptr;
  std::unique_ptr<AnalyticShape> shape;  // analytic geoms only, posed at the identity
  std::vector<int> geom_of_triangle;     // triangle geoms only
};

// Where a hit came from: MuJoCo geom id, or -1 on a miss.
struct GeomLookup {
  unsigned static_instance = RTC_INVALID_GEOMETRY_ID;  // top-scene id of the static instance
  std::vector<int> static_geom_of_geometry;            // static scene geometry id -> geom
  std::vector<int> static_geom_of_triangle;
  std::vector<int> moving_index_of_instance;  // top-scene id -> index into moving

  int Find(unsigned inst_id, unsigned geom_id, unsigned prim_id,
           const std::vector<MovingGeom>& moving) const {
    if (geom_id == RTC_INVALID_GEOMETRY_ID) return -1;
    if (inst_id != RTC_INVALID_GEOMETRY_ID && inst_id != static_instance) {
      const MovingGeom& mg = moving[moving_index_of_instance[inst_id]];
      return mg.shape ? mg.geom : mg.geom_of_triangle[prim_id];
    }
    const int geom = static_geom_of_geometry[geom_id];
    return geom == kGeomIsPrimId ? static_cast<int>(prim_id) : static_geom_of_triangle[prim_id];
  }
};

class EmbreeRayCaster final : public RayCaster {
 public:
  EmbreeRayCaster(const mjModel* model, const mjData* data, const RayCasterOptions& options)
      : model_(model), data_(data) {
    const std::vector<char> excluded = detail::ExcludedGeoms(model, options);
    std::vector<int> static_geoms;
    for (int g = 0; g < model->ngeom; ++g) {
      if (excluded[g] || detail::MjRaySkips(model, g)) continue;
      if (detail::GeomMoves(model, g)) {
        moving_.push_back(MakeMovingGeom(g));
      } else {
        static_geoms.push_back(g);
      }
    }
    BuildStaticScene(static_geoms);
    BuildTopScene();
    ChoosePacketWidth(options);
    Refresh();
  }

  ~EmbreeRayCaster() override {
    if (top_ != static_) rtcReleaseScene(top_);
    rtcReleaseScene(static_);
    for (MovingGeom& mg : moving_) rtcReleaseScene(mg.scene);
  }

  void Cast(const float* origins, const float* directions, std::size_t n, float max_range_m,
            float* range_m, int* geom_id) const override {
    switch (packet_width_) {
      case 16:
        CastPackets<RTCRayHit16, 16>(origins, directions, n, max_range_m, range_m, geom_id);
        return;
      case 8:
        CastPackets<RTCRayHit8, 8>(origins, directions, n, max_range_m, range_m, geom_id);
        return;
      default:
        CastSingle(origins, directions, n, max_range_m, range_m, geom_id);
        return;
    }
  }

  // Cast reads the Embree scenes only, never the mjData: static without moving geoms.
  bool Static() const override { return moving_.empty(); }

  void Refresh() override {
    if (moving_.empty()) return;
    float xfm[12];
    for (const MovingGeom& mg : moving_) {
      ToEmbreeTransform(data_->geom_xpos + 3 * mg.geom, data_->geom_xmat + 9 * mg.geom, xfm);
      rtcSetGeometryTransform(mg.instance, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, xfm);
      rtcCommitGeometry(mg.instance);
    }
    rtcCommitScene(top_);
    device_->Check("refreshing moving geoms");
  }

 private:
  MovingGeom MakeMovingGeom(int g) {
    static constexpr double kZero[3] = {0, 0, 0};
    static constexpr double kIdentity[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    MovingGeom mg;
    mg.geom = g;
    mg.scene = NewScene(*device_, RTC_BUILD_QUALITY_HIGH);
    if (detail::IsAnalytic(model_->geom_type[g])) {
      mg.shape = std::make_unique<AnalyticShape>(MakeShape(model_, g, kZero, kIdentity));
      AttachShapes(*device_, mg.scene, mg.shape.get(), 1);
    } else {
      TriangleSoup soup;
      detail::AppendTriangles(model_, g, kZero, kIdentity, &soup);
      mg.geom_of_triangle = std::move(soup.geom_of_triangle);
      AttachTriangles(*device_, mg.scene, soup);
    }
    rtcCommitScene(mg.scene);
    device_->Check("building a moving geom's scene");
    return mg;
  }

  // Static geoms are posed once, in world coordinates, from the mjData at construction.
  void BuildStaticScene(const std::vector<int>& geoms) {
    static_ = NewScene(*device_, RTC_BUILD_QUALITY_HIGH);
    TriangleSoup soup;
    for (int g : geoms) {
      const double* pos = data_->geom_xpos + 3 * g;
      const double* mat = data_->geom_xmat + 9 * g;
      if (detail::IsAnalytic(model_->geom_type[g])) {
        static_shapes_.push_back(MakeShape(model_, g, pos, mat));
      } else {
        detail::AppendTriangles(model_, g, pos, mat, &soup);
      }
    }
    auto set_geom = [this](unsigned id, int geom) {
      lookup_.static_geom_of_geometry.resize(
          std::max<std::size_t>(lookup_.static_geom_of_geometry.size(), id + 1), -1);
      lookup_.static_geom_of_geometry[id] = geom;
    };
    if (!soup.indices.empty()) {
      set_geom(AttachTriangles(*device_, static_, soup), 0);
      lookup_.static_geom_of_triangle = std::move(soup.geom_of_triangle);
    }
    if (!static_shapes_.empty()) {
      set_geom(AttachShapes(*device_, static_, static_shapes_.data(), static_shapes_.size()),
               kGeomIsPrimId);
    }
    rtcCommitScene(static_);
    device_->Check("building the static scene");
  }

  void BuildTopScene() {
    if (moving_.empty()) {
      top_ = static_;
      return;
    }
    top_ = NewScene(*device_, RTC_BUILD_QUALITY_LOW);
    rtcSetSceneFlags(top_, RTC_SCENE_FLAG_DYNAMIC | RTC_SCENE_FLAG_ROBUST);
    lookup_.static_instance = AttachInstance(static_);
    for (std::size_t i = 0; i < moving_.size(); ++i) {
      const unsigned id = AttachInstance(moving_[i].scene, &moving_[i].instance);
      lookup_.moving_index_of_instance.resize(
          std::max<std::size_t>(lookup_.moving_index_of_instance.size(), id + 1), -1);
      lookup_.moving_index_of_instance[id] = static_cast<int>(i);
    }
    device_->Check("building the top scene");
  }

  // Instances `scene` into the top scene at the identity; returns the instance's id.
  unsigned AttachInstance(RTCScene scene, RTCGeometry* instance_out = nullptr) {
    RTCGeometry instance = rtcNewGeometry(device_->get(), RTC_GEOMETRY_TYPE_INSTANCE);
    rtcSetGeometryInstancedScene(instance, scene);
    const float identity[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
    rtcSetGeometryTransform(instance, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, identity);
    rtcCommitGeometry(instance);
    const unsigned id = rtcAttachGeometry(top_, instance);
    rtcReleaseGeometry(instance);  // the scene keeps a reference
    if (instance_out != nullptr) *instance_out = instance;
    return id;
  }

  void ChoosePacketWidth(const RayCasterOptions& options) {
    const RTCDevice device = device_->get();
    if (!options.coherent_packets) {
      packet_width_ = 1;
    } else if (rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED)) {
      packet_width_ = 16;
    } else {
      packet_width_ = 8;
    }
  }

  // Packets of W consecutive rays: a scan line's neighbouring beams travel together through the
  // BVH (RTC_INTERSECT_CONTEXT_FLAG_COHERENT), the last packet masked by `valid`.
  template <typename RayHitW, int W>
  void CastPackets(const float* origins, const float* directions, std::size_t n, float max_range_m,
                   float* range_m, int* geom_id) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    alignas(64) RayHitW packet;
    alignas(64) int valid[W];
    float norm[W];
    for (std::size_t base = 0; base < n; base += W) {
      const std::size_t count = std::min<std::size_t>(W, n - base);
      for (int k = 0; k < W; ++k) {
        const std::size_t i = base + std::min<std::size_t>(k, count - 1);
        const float* o = origins + 3 * i;
        const float* d = directions + 3 * i;
        norm[k] = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        valid[k] = (static_cast<std::size_t>(k) < count && norm[k] > 0.0f) ? -1 : 0;
        packet.ray.org_x[k] = o[0];
        packet.ray.org_y[k] = o[1];
        packet.ray.org_z[k] = o[2];
        packet.ray.dir_x[k] = d[0];
        packet.ray.dir_y[k] = d[1];
        packet.ray.dir_z[k] = d[2];
        packet.ray.tnear[k] = 0.0f;
        packet.ray.tfar[k] = valid[k] ? max_range_m / norm[k] : -1.0f;
        packet.ray.time[k] = 0.0f;
        packet.ray.mask[k] = ~0u;
        packet.ray.id[k] = 0;
        packet.ray.flags[k] = 0;
        packet.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
        packet.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
      }
      Intersect(valid, &context, &packet);
      for (std::size_t k = 0; k < count; ++k) {
        const int geom = valid[k] ? lookup_.Find(packet.hit.instID[0][k], packet.hit.geomID[k],
                                                 packet.hit.primID[k], moving_)
                                  : -1;
        range_m[base + k] = geom >= 0 ? packet.ray.tfar[k] * norm[k] : kInf;
        if (geom_id != nullptr) geom_id[base + k] = geom;
      }
    }
  }

  void Intersect(int* valid, RTCIntersectContext* context, RTCRayHit16* packet) const {
    rtcIntersect16(valid, top_, context, packet);
  }
  void Intersect(int* valid, RTCIntersectContext* context, RTCRayHit8* packet) const {
    rtcIntersect8(valid, top_, context, packet);
  }

  // One rtcIntersect1 per ray: the baseline the packets are measured against.
  void CastSingle(const float* origins, const float* directions, std::size_t n, float max_range_m,
                  float* range_m, int* geom_id) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    for (std::size_t i = 0; i < n; ++i) {
      const float* o = origins + 3 * i;
      const float* d = directions + 3 * i;
      const float norm = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      RTCRayHit rh;
      rh.ray = {o[0], o[1], o[2], 0.0f, d[0], d[1], d[2], 0.0f, max_range_m / norm, ~0u, 0, 0};
      rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
      rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
      if (norm > 0.0f) rtcIntersect1(top_, &context, &rh);
      const int geom = lookup_.Find(rh.hit.instID[0], rh.hit.geomID, rh.hit.primID, moving_);
      range_m[i] = geom >= 0 ? rh.ray.tfar * norm : kInf;
      if (geom_id != nullptr) geom_id[i] = geom;
    }
  }

  static constexpr float kInf = std::numeric_limits<float>::infinity();

  const mjModel* model_;
  const mjData* data_;
  std::unique_ptr<Device> device_ = std::make_unique<Device>();
  RTCScene static_ = nullptr;
  RTCScene top_ = nullptr;
  std::vector<AnalyticShape> static_shapes_;  // user geometry data: must not reallocate after build
  std::vector<MovingGeom> moving_;
  GeomLookup lookup_;
  int packet_width_ = 16;
};

}  // namespace

std::unique_ptr<RayCaster> MakeEmbreeRayCaster(const mjModel_* model, const mjData_* data,
                                               const RayCasterOptions& options) {
  if (model == nullptr || data == nullptr) {
    throw std::runtime_error("MakeEmbreeRayCaster: model and data must not be null");
  }
  return std::make_unique<EmbreeRayCaster>(model, data, options);
}

}  // namespace pitchlab::sensors
