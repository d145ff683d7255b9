// Ray-casts a mesh scene (mesh_scene.h) with Intel Embree 3 into the raw frames a calibrated
// camera would take (mesh_camera.h), with per-pixel truth beside each frame.
//
// Per pixel: four rays on a rotated grid make the colour (antialiasing), one more through the
// pixel centre makes the truth (depth, plot, plant, vegetation), all through the inverse of the
// camera's distortion model. Shading is Lambertian: sun (with shadow rays) plus a sky ambient
// term, leaf translucency for back-lit blades, 3D value-noise texture at the hit point (the same
// pattern from every camera, which stereo needs). Rays that hit nothing see a bright, nearly
// uniform sky. Then vignetting, per-camera exposure, shot and read noise, and the one colour
// channel the Bayer filter passes at that pixel, rounded to 8 bits: the camera's RAW8.
//
// Thread contract: MeshRenderDevice and MeshRenderScene are thread-compatible once built;
// renderMeshFrame and camerasSeeing only read the scene and may run concurrently on it. The work
// inside one call runs on OpenCV's thread pool (cv::parallel_for_). Output depends only on the
// inputs and the noise key, not on thread count or scheduling.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <cstdint>
#include <memory>
#include <vector>

#include "fieldrig/core/pixel_format.h"
#include "fieldrig/core/result.h"
#include "fieldrig/sim/mesh_camera.h"
#include "fieldrig/sim/mesh_scene.h"

namespace fieldrig::sim {

// One Embree device (its thread pool and memory) for the process' scenes.
class MeshRenderDevice {
 public:
  static core::Result<std::shared_ptr<MeshRenderDevice>> create();
  ~MeshRenderDevice();
  MeshRenderDevice(const MeshRenderDevice&) = delete;
  MeshRenderDevice& operator=(const MeshRenderDevice&) = delete;
  void* handle() const { return device_; }  // RTCDevice

 private:
  explicit MeshRenderDevice(void* device) : device_(device) {}
  void* device_ = nullptr;
};

// A built scene: the meshes (kept for shading normals and materials) and Embree's BVH over them.
class MeshRenderScene {
 public:
  static core::Result<std::unique_ptr<MeshRenderScene>> build(
      std::shared_ptr<MeshRenderDevice> device, MeshScene scene);
  ~MeshRenderScene();
  MeshRenderScene(const MeshRenderScene&) = delete;
  MeshRenderScene& operator=(const MeshRenderScene&) = delete;

  const MeshScene& scene() const { return scene_; }
  void* handle() const { return rtc_scene_; }  // RTCScene
  // The scene part an Embree geometry id stands for.
  const MeshPart& part(unsigned geometry_id) const { return scene_.parts[geometry_id]; }

 private:
  MeshRenderScene(std::shared_ptr<MeshRenderDevice> device, MeshScene scene)
      : device_(std::move(device)), scene_(std::move(scene)) {}
  std::shared_ptr<MeshRenderDevice> device_;
  MeshScene scene_;
  void* rtc_scene_ = nullptr;
};

struct MeshRenderOptions {
  int samples_per_pixel = 4;  // colour rays per pixel: 1 (centre) or 4 (rotated grid)
  bool shadows = true;
  // Towards the sun, plot frame (x up, y along the row, z away from the cameras); normalised.
  Eigen::Vector3d sun_direction{0.77, 0.35, -0.53};
  double sun_irradiance = 1.0;
  double sky_ambient = 0.3;  // diffuse light from the sky, relative to the sun's
  // Raw value (0–255) of a white Lambertian surface lit by the sun at normal incidence.
  double exposure_dn = 600.0;
  double exposure_gain = 1.0;  // this camera's gain relative to the others
  // The sky's raw value per colour channel (B, G, R): bright and nearly textureless.
  Eigen::Vector3d sky_dn{255.0, 246.0, 228.0};
  double sky_gradient_dn = 12.0;  // darker towards the horizon by up to this much
  double vignetting = 0.12;       // relative fall-off at the image corners
  double read_noise_dn = 0.6;     // sigma
  double shot_noise_dn = 0.02;    // variance per DN of signal
  core::PixelFormat pixel_format = core::PixelFormat::kBayerRG8;
  std::uint64_t noise_key = 1;  // sensor noise seed (per camera and frame)
  bool truth_maps = true;       // depth, plot, plant and vegetation maps
};

// One camera's frame and the truth of every pixel's centre ray.
struct MeshFrame {
  cv::Mat raw;         // CV_8UC1, Bayer pattern of options.pixel_format (or grey for Mono8)
  cv::Mat depth;       // CV_32F: z of the surface in this camera's own frame, m; 0: sky
  cv::Mat plot;        // CV_8UC1: PlotCode of the surface (0: soil, clods, sky)
  cv::Mat plant;       // CV_16UC1: MeshPlant::id (0: not a plant)
  cv::Mat vegetation;  // CV_8UC1: 255 on a plant of any plot or the distant canopy, else 0
};

// Renders one camera. `rays` is pixelRayMap(camera).
MeshFrame renderMeshFrame(const MeshRenderScene& scene, const MeshCamera& camera,
                          const cv::Mat& rays, const MeshRenderOptions& options);

// For each point, which of the cameras (at most 8) see it, as a bit mask (bit c: cameras[c]): a
// camera sees a point inside its image (distortion applied) with nothing of the scene between
// the camera and the point (1 mm before it).
std::vector<std::uint8_t> camerasSeeing(const MeshRenderScene& scene,
                                        const std::vector<MeshCamera>& cameras,
                                        const std::vector<Eigen::Vector3f>& points);

// The surface a single ray meets first, for tests and truth: distance along the unit
// direction (infinity when nothing), the part hit (-1 when nothing).
struct RayHit {
  double distance = 0.0;
  int part = -1;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // geometric, unit
};
RayHit castRay(const MeshRenderScene& scene, const Eigen::Vector3d& origin,
               const Eigen::Vector3d& direction);

}  // namespace fieldrig::sim
