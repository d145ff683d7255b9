#include "fieldrig/stem/measurement_json.h"

namespace fieldrig::stem {
namespace {

nlohmann::ordered_json pointsJson(const Points4& points) {
  nlohmann::ordered_json out = nlohmann::ordered_json::array();
  for (const cv::Point2d& p : points)
    out.push_back({p.x, p.y});
  return out;
}

}  // namespace

nlohmann::ordered_json toJson(const StemMeasurement& m) {
  nlohmann::ordered_json out;
  out["status"] = std::string(toString(m.status));
  if (!m.ok())
    out["message"] = m.message;
  const bool matched = m.ok() || m.status == MeasureStatus::kWeakMatch;
  out["diameter_mm"] = m.ok() ? nlohmann::ordered_json(m.diameter_mm) : nullptr;
  out["disparity_px"] = matched ? nlohmann::ordered_json(m.disparity_px) : nullptr;
  out["ncc"] = matched ? nlohmann::ordered_json(m.ncc) : nullptr;
  out["ncc_second"] = matched ? nlohmann::ordered_json(m.ncc_second) : nullptr;
  out["distinctness"] = matched ? nlohmann::ordered_json(m.distinctness) : nullptr;
  out["diameter_plane_mm"] = m.ok() ? nlohmann::ordered_json(m.diameter_plane_mm) : nullptr;
  out["patch_depth_m"] = m.ok() ? nlohmann::ordered_json(m.patch_depth_m) : nullptr;
  out["width_px"] = {{"d12", m.width.d12}, {"d34", m.width.d34}, {"d", m.width.d}};
  out["edges_refined"] = m.edges_refined;
  out["edge_samples"] = {m.edge_samples_left, m.edge_samples_right};
  out["quadrangle_rectified"] = pointsJson(toPoints(m.refined));
  out["clicked_rectified"] = pointsJson(toPoints(m.clicked));
  out["right_patch_raw"] = matched ? pointsJson(m.right_patch_raw) : nullptr;
  out["elapsed_ms"] = m.elapsed_ms;
  return out;
}

}  // namespace fieldrig::stem
