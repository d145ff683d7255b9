#include "fieldrig/sim/mesh_renderer.h"

#include <embree3/rtcore.h>
#include <xmmintrin.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "value_noise.h"

namespace fieldrig::sim {
namespace {

// A tile of 4 × 2 pixels: one 8-ray packet per sample position. Eight rays are the width of
// Embree's AVX2 kernels on this machine; with 16-ray packets (4 × 4 tiles) the mature plot's
// FrameSet took 0.2 s (6 %) longer on average over five alternated runs of
// bench/mesh_render_bench, with the same frames bit for bit.
constexpr int kTileW = 4;
constexpr int kTileH = 2;
constexpr int kPacket = kTileW * kTileH;
static_assert(kPacket % 4 == 0, "an edge pixel's four samples share one packet");
constexpr float kInfinity = std::numeric_limits<float>::infinity();

// Embree asks for flush-to-zero and denormals-are-zero on the threads that trace; the previous
// mode is restored so that nothing else running on OpenCV's pool sees a change.
class FlushDenormals {
 public:
  FlushDenormals() : saved_(_mm_getcsr()) { _mm_setcsr(saved_ | 0x8040U); }
  ~FlushDenormals() { _mm_setcsr(saved_); }
  FlushDenormals(const FlushDenormals&) = delete;
  FlushDenormals& operator=(const FlushDenormals&) = delete;

 private:
  unsigned int saved_;
};

std::string deviceError(RTCDevice device) {
  switch (rtcGetDeviceError(device)) {
    case RTC_ERROR_NONE:
      return "no error";
    case RTC_ERROR_INVALID_ARGUMENT:
      return "invalid argument";
    case RTC_ERROR_INVALID_OPERATION:
      return "invalid operation";
    case RTC_ERROR_OUT_OF_MEMORY:
      return "out of memory";
    case RTC_ERROR_UNSUPPORTED_CPU:
      return "unsupported CPU";
    case RTC_ERROR_CANCELLED:
      return "cancelled";
    default:
      return "unknown error";
  }
}

// The colour channel (0 B, 1 G, 2 R) the filter passes at (row, col), GenICam pattern names
// (the name gives the first two pixels of the first row), as stereo::mosaicBayer has it.
std::array<std::array<int, 2>, 2> bayerChannels(core::PixelFormat format) {
  const char* pattern = "RGGB";
  switch (format) {
    case core::PixelFormat::kBayerGR8:
      pattern = "GRBG";
      break;
    case core::PixelFormat::kBayerGB8:
      pattern = "GBRG";
      break;
    case core::PixelFormat::kBayerBG8:
      pattern = "BGGR";
      break;
    default:
      break;
  }
  auto channel = [](char c) { return c == 'B' ? 0 : c == 'G' ? 1 : 2; };
  return {{{channel(pattern[0]), channel(pattern[1])}, {channel(pattern[2]), channel(pattern[3])}}};
}

// A surface point to shade, and where its light goes.
struct ShadePoint {
  Eigen::Vector3f position;
  Eigen::Vector3f normal;  // facing the camera
  const MeshPart* part = nullptr;
  int pixel = 0;           // index in the tile
  float weight = 0.0F;     // share of the pixel
  float footprint = 0.0F;  // a pixel's size at the point, m (texture octaves finer fade out)
  float direct = 0.0F;     // n·sun, signed (negative: lit from behind)
  bool wants_shadow_ray = false;
  bool lit = true;
};

const detail::TextureNoise& textureNoise() {
  static const detail::TextureNoise noise;
  return noise;
}

// An octave's weight: full while a pixel covers at most half a cell, none from a whole cell on
// (finer detail than the pixel would alias; the camera's optics average it out).
float octaveWeight(float footprint, float cell) {
  return std::clamp(2.0F - 2.0F * footprint / cell, 0.0F, 1.0F);
}

float texture(const Material& m, const Eigen::Vector3f& p, float footprint) {
  const detail::TextureNoise& noise = textureNoise();
  const float cell = m.texture_cell_m;
  const float inv = 1.0F / cell;
  const float w1 = 0.65F * octaveWeight(footprint, cell);
  const float w2 = 0.35F * octaveWeight(footprint, cell / 3.1F);
  float v = 0.0F;
  if (w1 > 0.0F)
    v += w1 * (noise(p.x() * inv, p.y() * inv, p.z() * inv) - 0.5F);
  if (w2 > 0.0F) {
    const float inv2 = 3.1F * inv;
    v += w2 * (noise(p.x() * inv2 + 17.3F, p.y() * inv2 + 5.1F, p.z() * inv2) - 0.5F);
  }
  return std::max(0.1F, 1.0F + m.texture_contrast * 3.2F * v);
}

struct Lighting {
  Eigen::Vector3f sun;
  float sun_irradiance;
  float sky_ambient;
};

// Radiance (B, G, R) relative to a white surface under the sun at normal incidence.
Eigen::Vector3f shade(const ShadePoint& s, const Lighting& light) {
  const Material& m = s.part->material;
  const float tex = texture(m, s.position, s.footprint);
  float irradiance = light.sky_ambient * (0.6F + 0.4F * std::clamp(s.normal.x(), -1.0F, 1.0F));
  if (s.lit) {
    if (s.direct > 0.0F)
      irradiance += light.sun_irradiance * s.direct;
    else
      irradiance += light.sun_irradiance * m.translucency * -s.direct;
  }
  const float k = tex * irradiance;
  return {m.albedo.z() * k, m.albedo.y() * k, m.albedo.x() * k};
}

void setRay(RTCRay8& ray, int lane, const Eigen::Vector3f& o, const Eigen::Vector3f& d,
            float tfar) {
  ray.org_x[lane] = o.x();
  ray.org_y[lane] = o.y();
  ray.org_z[lane] = o.z();
  ray.dir_x[lane] = d.x();
  ray.dir_y[lane] = d.y();
  ray.dir_z[lane] = d.z();
  ray.tnear[lane] = 0.0F;
  ray.tfar[lane] = tfar;
  ray.time[lane] = 0.0F;
  ray.mask[lane] = 0xFFFFFFFFU;
  ray.id[lane] = static_cast<unsigned>(lane);
  ray.flags[lane] = 0;
}

Eigen::Vector3f shadingNormal(const MeshPart& part, unsigned prim, float u, float v,
                              const Eigen::Vector3f& geometric_facing) {
  const auto& t = part.triangles[prim];
  Eigen::Vector3f n =
      (1.0F - u - v) * part.normals[t[0]] + u * part.normals[t[1]] + v * part.normals[t[2]];
  const float length = n.norm();
  n = length > 1e-12F ? Eigen::Vector3f(n / length) : geometric_facing;
  if (n.dot(geometric_facing) < 0.0F)
    n = -n;
  return n;
}

// What a ray met: enough to shade it and to say what the pixel shows.
struct Hit {
  float t = kInfinity;  // along the ray's direction (camera-z 1: the depth)
  unsigned geom = RTC_INVALID_GEOMETRY_ID;
  unsigned prim = 0;
  float u = 0.0F;
  float v = 0.0F;
  Eigen::Vector3f ng = Eigen::Vector3f::Zero();
  Eigen::Vector3f dir = Eigen::Vector3f::UnitZ();
};

Hit hitOf(const RTCRayHit8& packet, int lane) {
  Hit h;
  h.geom = packet.hit.geomID[lane];
  h.t = packet.ray.tfar[lane];
  h.prim = packet.hit.primID[lane];
  h.u = packet.hit.u[lane];
  h.v = packet.hit.v[lane];
  h.ng = Eigen::Vector3f(packet.hit.Ng_x[lane], packet.hit.Ng_y[lane], packet.hit.Ng_z[lane]);
  h.dir = Eigen::Vector3f(packet.ray.dir_x[lane], packet.ray.dir_y[lane], packet.ray.dir_z[lane]);
  return h;
}

struct EdgeKey {
  unsigned geom;
  float t;
};

struct RenderScratch {
  std::vector<Eigen::Vector3f> directions;
  std::vector<Hit> centres;
  std::vector<EdgeKey> keys;
};

void traceRays(RTCScene scene, RTCIntersectContext& context, RTCRayHit8& packet,
               std::array<int, kPacket>& valid, const Eigen::Vector3f& origin,
               const Eigen::Vector3f* directions, int count) {
  for (int lane = 0; lane < kPacket; ++lane) {
    const bool use = lane < count;
    valid[static_cast<std::size_t>(lane)] = use ? -1 : 0;
    setRay(packet.ray, lane, origin, use ? directions[lane] : Eigen::Vector3f::UnitZ(), kInfinity);
    packet.hit.geomID[lane] = RTC_INVALID_GEOMETRY_ID;
    packet.hit.instID[0][lane] = RTC_INVALID_GEOMETRY_ID;
  }
  rtcIntersect8(valid.data(), scene, &context, &packet);
}

}  // namespace

core::Result<std::shared_ptr<MeshRenderDevice>> MeshRenderDevice::create() {
  RTCDevice device = rtcNewDevice(nullptr);
  if (device == nullptr)
    return core::Error{"Embree: cannot create a device: " + deviceError(nullptr)};
  return std::shared_ptr<MeshRenderDevice>(new MeshRenderDevice(device));
}

MeshRenderDevice::~MeshRenderDevice() {
  if (device_ != nullptr)
    rtcReleaseDevice(static_cast<RTCDevice>(device_));
}

core::Result<std::unique_ptr<MeshRenderScene>> MeshRenderScene::build(
    std::shared_ptr<MeshRenderDevice> device, MeshScene scene) {
  auto* dev = static_cast<RTCDevice>(device->handle());
  std::unique_ptr<MeshRenderScene> built(new MeshRenderScene(std::move(device), std::move(scene)));
  RTCScene rtc = rtcNewScene(dev);
  if (rtc == nullptr)
    return core::Error{"Embree: cannot create a scene: " + deviceError(dev)};
  built->rtc_scene_ = rtc;
  rtcSetSceneBuildQuality(rtc, RTC_BUILD_QUALITY_HIGH);
  for (std::size_t i = 0; i < built->scene_.parts.size(); ++i) {
    const MeshPart& part = built->scene_.parts[i];
    RTCGeometry geometry = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vertices = static_cast<float*>(
        rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                3 * sizeof(float), std::max<std::size_t>(part.vertices.size(), 1)));
    auto* indices = static_cast<unsigned*>(
        rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                3 * sizeof(unsigned), part.triangles.size()));
    if (vertices == nullptr || (indices == nullptr && !part.triangles.empty())) {
      rtcReleaseGeometry(geometry);
      return core::Error{"Embree: cannot allocate a geometry of " +
                         std::to_string(part.triangles.size()) + " triangles: " + deviceError(dev)};
    }
    for (std::size_t v = 0; v < part.vertices.size(); ++v)
      for (int c = 0; c < 3; ++c)
        vertices[3 * v + static_cast<std::size_t>(c)] = part.vertices[v][c];
    for (std::size_t t = 0; t < part.triangles.size(); ++t)
      for (int c = 0; c < 3; ++c)
        indices[3 * t + static_cast<std::size_t>(c)] =
            part.triangles[t][static_cast<std::size_t>(c)];
    rtcCommitGeometry(geometry);
    rtcAttachGeometryByID(rtc, geometry, static_cast<unsigned>(i));
    rtcReleaseGeometry(geometry);
  }
  rtcCommitScene(rtc);
  if (rtcGetDeviceError(dev) != RTC_ERROR_NONE)
    return core::Error{"Embree: cannot build the scene: " + deviceError(dev)};
  return built;
}

MeshRenderScene::~MeshRenderScene() {
  if (rtc_scene_ != nullptr)
    rtcReleaseScene(static_cast<RTCScene>(rtc_scene_));
}

MeshFrame renderMeshFrame(const MeshRenderScene& render_scene, const MeshCamera& camera,
                          const cv::Mat& rays, const MeshRenderOptions& options) {
  CV_Assert(rays.type() == CV_32FC2 && rays.size() == camera.size);
  const int width = camera.size.width;
  const int height = camera.size.height;
  auto* scene = static_cast<RTCScene>(render_scene.handle());
  MeshFrame frame;
  frame.raw.create(camera.size, CV_8UC1);
  if (options.truth_maps) {
    frame.depth.create(camera.size, CV_32F);
    frame.plot.create(camera.size, CV_8UC1);
    frame.plant.create(camera.size, CV_16UC1);
    frame.vegetation.create(camera.size, CV_8UC1);
  }
  const Eigen::Matrix3f rotation = camera.plot_from_camera.cast<float>();
  const Eigen::Vector3f origin = camera.position.cast<float>();
  Lighting light;
  light.sun = options.sun_direction.normalized().cast<float>();
  light.sun_irradiance = static_cast<float>(options.sun_irradiance);
  light.sky_ambient = static_cast<float>(options.sky_ambient);
  const bool supersample = options.samples_per_pixel >= 4;
  // Rotated-grid supersampling: four offsets on a grid turned by atan(1/2).
  const std::array<std::array<float, 2>, 4> offsets = {
      {{-0.375F, -0.125F}, {0.125F, -0.375F}, {0.375F, 0.125F}, {-0.125F, 0.375F}}};
  const auto channels = bayerChannels(options.pixel_format);
  const bool mono = options.pixel_format == core::PixelFormat::kMono8;
  const double cx = camera.camera_matrix(0, 2);
  const double cy = camera.camera_matrix(1, 2);
  const double corner2 = std::max({cx * cx + cy * cy, (width - cx) * (width - cx) + cy * cy,
                                   cx * cx + (height - cy) * (height - cy),
                                   (width - cx) * (width - cx) + (height - cy) * (height - cy)});
  const float scale = static_cast<float>(options.exposure_dn * options.exposure_gain);
  const float inverse_focal = static_cast<float>(1.0 / camera.camera_matrix(0, 0));

  // Each pixel centre's ray in the plot frame, camera-z component 1.
  // Buffers reused from frame to frame by the calling thread (page faults on ~110 MB a frame would
  // cost more than some of the rays).
  thread_local RenderScratch scratch;
  std::vector<Eigen::Vector3f>& directions = scratch.directions;
  directions.resize(static_cast<std::size_t>(width) * height);
  cv::parallel_for_(cv::Range(0, height), [&](const cv::Range& range) {
    for (int row = range.start; row < range.end; ++row) {
      const auto* n = rays.ptr<cv::Vec2f>(row);
      for (int col = 0; col < width; ++col)
        directions[static_cast<std::size_t>(row) * width + col] =
            rotation * Eigen::Vector3f(n[col][0], n[col][1], 1.0F);
    }
  });
  auto directionAt = [&](int col, int row) -> const Eigen::Vector3f& {
    return directions[static_cast<std::size_t>(row) * width + col];
  };
  // A sample at (col + dx, row + dy): the centres' rays interpolated to first order.
  auto sampleDirection = [&](int col, int row, float dx, float dy) {
    const int c0 = std::max(col - 1, 0);
    const int c1 = std::min(col + 1, width - 1);
    const int r0 = std::max(row - 1, 0);
    const int r1 = std::min(row + 1, height - 1);
    const Eigen::Vector3f du =
        (directionAt(c1, row) - directionAt(c0, row)) / static_cast<float>(std::max(c1 - c0, 1));
    const Eigen::Vector3f dv =
        (directionAt(col, r1) - directionAt(col, r0)) / static_cast<float>(std::max(r1 - r0, 1));
    return Eigen::Vector3f(directionAt(col, row) + dx * du + dy * dv);
  };

  const int tiles_x = (width + kTileW - 1) / kTileW;
  const int tiles_y = (height + kTileH - 1) / kTileH;
  // Pass 1: the ray through every pixel centre (the truth, and the colour where the pixel shows
  // one surface).
  std::vector<Hit>& centres = scratch.centres;
  centres.resize(static_cast<std::size_t>(width) * height);
  // What the edge test reads of every pixel, packed (8 bytes, not a whole hit).
  std::vector<EdgeKey>& keys = scratch.keys;
  keys.resize(centres.size());
  cv::parallel_for_(cv::Range(0, tiles_y), [&](const cv::Range& range) {
    const FlushDenormals flush;
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    alignas(64) RTCRayHit8 packet;
    alignas(64) std::array<int, kPacket> valid{};  // Embree reads it aligned
    std::array<Eigen::Vector3f, kPacket> dirs;
    std::array<int, kPacket> index{};
    for (int ty = range.start; ty < range.end; ++ty) {
      for (int tx = 0; tx < tiles_x; ++tx) {
        int count = 0;
        for (int lane = 0; lane < kPacket; ++lane) {
          const int col = tx * kTileW + lane % kTileW;
          const int row = ty * kTileH + lane / kTileW;
          if (col >= width || row >= height)
            continue;
          index[static_cast<std::size_t>(count)] = row * width + col;
          dirs[static_cast<std::size_t>(count)] = directionAt(col, row);
          ++count;
        }
        traceRays(scene, context, packet, valid, origin, dirs.data(), count);
        for (int lane = 0; lane < count; ++lane) {
          const auto i = static_cast<std::size_t>(index[static_cast<std::size_t>(lane)]);
          centres[i] = hitOf(packet, lane);
          keys[i] = {centres[i].geom, centres[i].t};
        }
      }
    }
  });

  // Pass 2: pixels whose neighbourhood shows another surface or a depth step are edges and get
  // the four rotated-grid rays; then shading, shadow rays, exposure, noise, the Bayer filter.
  cv::parallel_for_(cv::Range(0, tiles_y), [&](const cv::Range& range) {
    const FlushDenormals flush;
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    RTCIntersectContext shadow_context;
    rtcInitIntersectContext(&shadow_context);
    shadow_context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;  // parallel rays from one tile
    alignas(64) RTCRayHit8 packet;
    alignas(64) RTCRay8 shadow;
    alignas(64) std::array<int, kPacket> valid{};  // Embree reads it aligned
    std::array<Eigen::Vector3f, kPacket> dirs;
    std::vector<Hit> sample_hits(4 * kPacket);
    std::vector<ShadePoint> points;
    points.reserve(4 * kPacket);
    std::array<Eigen::Vector3f, kPacket> colour;
    std::array<bool, kPacket> edge{};
    auto isEdge = [&](int col, int row) {
      const EdgeKey& c = keys[static_cast<std::size_t>(row) * width + col];
      // The four direct neighbours: a boundary through the pixel shows in one of them.
      constexpr std::array<std::array<int, 2>, 4> kNeighbours{{{-1, 0}, {1, 0}, {0, -1}, {0, 1}}};
      for (const auto& [dx, dy] : kNeighbours) {
        const int u = std::clamp(col + dx, 0, width - 1);
        const int v = std::clamp(row + dy, 0, height - 1);
        const EdgeKey& n = keys[static_cast<std::size_t>(v) * width + u];
        if (n.geom != c.geom)
          return true;
        if (c.geom != RTC_INVALID_GEOMETRY_ID && std::abs(n.t - c.t) > 0.04F * c.t)
          return true;
      }
      return false;
    };
    auto addPoint = [&](const Hit& h, int lane, float weight) {
      const MeshPart& part = render_scene.part(h.geom);
      Eigen::Vector3f ng = h.ng.normalized();
      if (ng.dot(h.dir) > 0.0F)
        ng = -ng;
      ShadePoint point;
      point.position = origin + h.t * h.dir;
      point.normal = shadingNormal(part, h.prim, h.u, h.v, ng);
      point.part = &part;
      point.pixel = lane;
      point.weight = weight;
      point.footprint = h.t * inverse_focal;
      point.direct = point.normal.dot(light.sun);
      // The geometric normal decides which side the sun is on (shading normals bend).
      if (ng.dot(light.sun) <= 0.0F && point.direct > 0.0F)
        point.direct = 0.0F;
      point.wants_shadow_ray =
          options.shadows &&
          (point.direct > 0.0F || (point.direct < 0.0F && part.material.translucency > 0.0F));
      point.lit = !options.shadows;
      points.push_back(point);
    };
    auto skyColour = [&](const Eigen::Vector3f& d) {
      const float up = std::clamp(d.x() / d.norm(), 0.0F, 1.0F);
      const float darker = static_cast<float>(options.sky_gradient_dn) * (1.0F - up);
      return Eigen::Vector3f((options.sky_dn.cast<float>() - Eigen::Vector3f::Constant(darker)) /
                             scale);
    };

    for (int ty = range.start; ty < range.end; ++ty) {
      for (int tx = 0; tx < tiles_x; ++tx) {
        auto pixelOf = [&](int lane, int& col, int& row) {
          col = tx * kTileW + lane % kTileW;
          row = ty * kTileH + lane / kTileW;
          return col < width && row < height;
        };
        // The edges' four samples, two pixels to a packet.
        int edges = 0;
        std::array<int, kPacket> edge_lanes{};
        for (int lane = 0; lane < kPacket; ++lane) {
          int col = 0;
          int row = 0;
          edge[static_cast<std::size_t>(lane)] =
              supersample && pixelOf(lane, col, row) && isEdge(col, row);
          if (edge[static_cast<std::size_t>(lane)])
            edge_lanes[static_cast<std::size_t>(edges++)] = lane;
        }
        for (int first = 0; first < edges; first += kPacket / 4) {
          const int pixels = std::min(kPacket / 4, edges - first);
          for (int p = 0; p < pixels; ++p) {
            int col = 0;
            int row = 0;
            pixelOf(edge_lanes[static_cast<std::size_t>(first + p)], col, row);
            for (int s = 0; s < 4; ++s)
              dirs[static_cast<std::size_t>(4 * p + s)] =
                  sampleDirection(col, row, offsets[static_cast<std::size_t>(s)][0],
                                  offsets[static_cast<std::size_t>(s)][1]);
          }
          traceRays(scene, context, packet, valid, origin, dirs.data(), 4 * pixels);
          for (int r = 0; r < 4 * pixels; ++r)
            sample_hits[static_cast<std::size_t>(4 * first + r)] = hitOf(packet, r);
        }

        points.clear();
        int edge_index = 0;
        for (int lane = 0; lane < kPacket; ++lane) {
          int col = 0;
          int row = 0;
          colour[static_cast<std::size_t>(lane)].setZero();
          if (!pixelOf(lane, col, row))
            continue;
          if (edge[static_cast<std::size_t>(lane)]) {
            // Samples on the same surface (same part, depths within 2 %) are shaded once, at
            // their mean point: an edge pixel usually shows two surfaces, not four.
            std::array<bool, 4> done{};
            for (int s = 0; s < 4; ++s) {
              if (done[static_cast<std::size_t>(s)])
                continue;
              const Hit& h = sample_hits[static_cast<std::size_t>(4 * edge_index + s)];
              if (h.geom == RTC_INVALID_GEOMETRY_ID) {
                colour[static_cast<std::size_t>(lane)] += 0.25F * skyColour(h.dir);
                continue;
              }
              Hit mean = h;
              Eigen::Vector3f point = h.t * h.dir;
              int members = 1;
              for (int o = s + 1; o < 4; ++o) {
                const Hit& other = sample_hits[static_cast<std::size_t>(4 * edge_index + o)];
                if (!done[static_cast<std::size_t>(o)] && other.geom == h.geom &&
                    std::abs(other.t - h.t) < 0.02F * h.t) {
                  done[static_cast<std::size_t>(o)] = true;
                  point += other.t * other.dir;
                  ++members;
                }
              }
              if (members > 1) {
                // Shaded at the members' mean point, along the first member's ray.
                mean.t = point.norm() / h.dir.norm() / static_cast<float>(members);
                mean.dir = point / (point.norm() / h.dir.norm());
              }
              addPoint(mean, lane, 0.25F * static_cast<float>(members));
            }
            ++edge_index;
          } else {
            const Hit& h = centres[static_cast<std::size_t>(row) * width + col];
            if (h.geom == RTC_INVALID_GEOMETRY_ID)
              colour[static_cast<std::size_t>(lane)] = skyColour(h.dir);
            else
              addPoint(h, lane, 1.0F);
          }
        }
        // Shadow rays towards the sun, a packet at a time, from just off the lit side.
        for (std::size_t first = 0; first < points.size(); first += kPacket) {
          bool any = false;
          for (int lane = 0; lane < kPacket; ++lane) {
            const std::size_t i = first + static_cast<std::size_t>(lane);
            const bool use = i < points.size() && points[i].wants_shadow_ray;
            valid[static_cast<std::size_t>(lane)] = use ? -1 : 0;
            any = any || use;
            Eigen::Vector3f o = Eigen::Vector3f::Zero();
            if (use) {
              const ShadePoint& p = points[i];
              o = p.position + (p.direct > 0.0F ? 5e-4F : -5e-4F) * p.normal;
            }
            setRay(shadow, lane, o, light.sun, kInfinity);
          }
          if (!any)
            continue;
          rtcOccluded8(valid.data(), scene, &shadow_context, &shadow);
          for (int lane = 0; lane < kPacket; ++lane) {
            const std::size_t i = first + static_cast<std::size_t>(lane);
            if (i < points.size() && points[i].wants_shadow_ray)
              points[i].lit = shadow.tfar[lane] >= 0.0F;
          }
        }
        for (const ShadePoint& p : points)
          colour[static_cast<std::size_t>(p.pixel)] += p.weight * shade(p, light);

        // Exposure, vignetting, noise, the Bayer filter; truth from the centre ray.
        for (int lane = 0; lane < kPacket; ++lane) {
          int col = 0;
          int row = 0;
          if (!pixelOf(lane, col, row))
            continue;
          const double dx = col - cx;
          const double dy = row - cy;
          const auto vignette =
              static_cast<float>(1.0 - options.vignetting * (dx * dx + dy * dy) / corner2);
          const Eigen::Vector3f& c = colour[static_cast<std::size_t>(lane)];
          float value = 0.0F;
          if (mono)
            value = 0.114F * c.x() + 0.587F * c.y() + 0.299F * c.z();
          else
            value =
                c[channels[static_cast<std::size_t>(row % 2)][static_cast<std::size_t>(col % 2)]];
          value *= scale * vignette;
          const auto pixel_index =
              static_cast<std::uint64_t>(row) * static_cast<std::uint64_t>(width) +
              static_cast<std::uint64_t>(col);
          const float sigma =
              std::sqrt(static_cast<float>(options.read_noise_dn * options.read_noise_dn) +
                        static_cast<float>(options.shot_noise_dn) * std::max(value, 0.0F));
          value += sigma *
                   detail::gaussianApprox(options.noise_key * 0x9E3779B97F4A7C15ULL + pixel_index);
          frame.raw.at<std::uint8_t>(row, col) =
              static_cast<std::uint8_t>(std::clamp(value + 0.5F, 0.0F, 255.0F));
          if (options.truth_maps) {
            const Hit& h = centres[static_cast<std::size_t>(row) * width + col];
            if (h.geom == RTC_INVALID_GEOMETRY_ID) {
              frame.depth.at<float>(row, col) = 0.0F;
              frame.plot.at<std::uint8_t>(row, col) = 0;
              frame.plant.at<std::uint16_t>(row, col) = 0;
              frame.vegetation.at<std::uint8_t>(row, col) = 0;
            } else {
              const MeshPart& part = render_scene.part(h.geom);
              // The direction's camera-z component is 1, so the ray parameter is the depth.
              frame.depth.at<float>(row, col) = h.t;
              frame.plot.at<std::uint8_t>(row, col) = static_cast<std::uint8_t>(part.plot);
              frame.plant.at<std::uint16_t>(row, col) = part.plant_id;
              frame.vegetation.at<std::uint8_t>(row, col) =
                  isPlantPart(part.kind) || part.kind == PartKind::kFarCanopy ? 255 : 0;
            }
          }
        }
      }
    }
  });
  return frame;
}

std::vector<std::uint8_t> camerasSeeing(const MeshRenderScene& render_scene,
                                        const std::vector<MeshCamera>& cameras,
                                        const std::vector<Eigen::Vector3f>& points) {
  CV_Assert(cameras.size() <= 8);  // one bit each in a byte
  std::vector<std::uint8_t> visible(points.size(), 0);
  auto* scene = static_cast<RTCScene>(render_scene.handle());
  const int blocks = static_cast<int>((points.size() + kPacket - 1) / kPacket);
  cv::parallel_for_(cv::Range(0, blocks), [&](const cv::Range& range) {
    const FlushDenormals flush;
    alignas(64) RTCRay8 rays;
    alignas(64) std::array<int, kPacket> valid{};  // Embree reads it aligned
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    for (int block = range.start; block < range.end; ++block) {
      const std::size_t first = static_cast<std::size_t>(block) * kPacket;
      for (std::size_t c = 0; c < cameras.size(); ++c) {
        const MeshCamera& camera = cameras[c];
        bool any = false;
        for (int lane = 0; lane < kPacket; ++lane) {
          const std::size_t i = first + static_cast<std::size_t>(lane);
          bool use = i < points.size();
          Eigen::Vector3d d = Eigen::Vector3d::UnitZ();
          if (use) {
            const Eigen::Vector3d p = points[i].cast<double>();
            Eigen::Vector2d pixel;
            use = camera.project(p, pixel) && pixel.x() >= -0.5 && pixel.y() >= -0.5 &&
                  pixel.x() < camera.size.width - 0.5 && pixel.y() < camera.size.height - 0.5;
            d = p - camera.position;
          }
          valid[static_cast<std::size_t>(lane)] = use ? -1 : 0;
          any = any || use;
          rays.org_x[lane] = static_cast<float>(camera.position.x());
          rays.org_y[lane] = static_cast<float>(camera.position.y());
          rays.org_z[lane] = static_cast<float>(camera.position.z());
          rays.dir_x[lane] = static_cast<float>(d.x());
          rays.dir_y[lane] = static_cast<float>(d.y());
          rays.dir_z[lane] = static_cast<float>(d.z());
          rays.tnear[lane] = 0.0F;
          rays.tfar[lane] = static_cast<float>(1.0 - 1e-3 / std::max(d.norm(), 1e-3));
          rays.time[lane] = 0.0F;
          rays.mask[lane] = 0xFFFFFFFFU;
          rays.id[lane] = static_cast<unsigned>(lane);
          rays.flags[lane] = 0;
        }
        if (!any)
          continue;
        rtcOccluded8(valid.data(), scene, &context, &rays);
        for (int lane = 0; lane < kPacket; ++lane) {
          const std::size_t i = first + static_cast<std::size_t>(lane);
          if (valid[static_cast<std::size_t>(lane)] != 0 && rays.tfar[lane] >= 0.0F)
            visible[i] = static_cast<std::uint8_t>(visible[i] | (1U << c));
        }
      }
    }
  });
  return visible;
}

RayHit castRay(const MeshRenderScene& render_scene, const Eigen::Vector3d& origin,
               const Eigen::Vector3d& direction) {
  const FlushDenormals flush;
  const Eigen::Vector3d d = direction.normalized();
  RTCRayHit hit{};
  hit.ray.org_x = static_cast<float>(origin.x());
  hit.ray.org_y = static_cast<float>(origin.y());
  hit.ray.org_z = static_cast<float>(origin.z());
  hit.ray.dir_x = static_cast<float>(d.x());
  hit.ray.dir_y = static_cast<float>(d.y());
  hit.ray.dir_z = static_cast<float>(d.z());
  hit.ray.tnear = 0.0F;
  hit.ray.tfar = kInfinity;
  hit.ray.mask = 0xFFFFFFFFU;
  hit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  hit.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  rtcIntersect1(static_cast<RTCScene>(render_scene.handle()), &context, &hit);
  RayHit result;
  if (hit.hit.geomID == RTC_INVALID_GEOMETRY_ID) {
    result.distance = std::numeric_limits<double>::infinity();
    return result;
  }
  result.distance = hit.ray.tfar;
  result.part = static_cast<int>(hit.hit.geomID);
  result.normal = Eigen::Vector3d(hit.hit.Ng_x, hit.hit.Ng_y, hit.hit.Ng_z).normalized();
  return result;
}

}  // namespace fieldrig::sim
