#include "fieldrig/daemon/link_status.h"

namespace fieldrig::daemon {

nlohmann::ordered_json linkStatusJson(const LinkSummary& link) {
  using Json = nlohmann::ordered_json;
  auto known = [](bool has, std::uint64_t count) { return has ? Json(count) : Json(nullptr); };
  Json cameras = Json::object();
  for (const LinkSummary::Camera& camera : link.cameras) {
    cameras[camera.name] = {
        {"resent", known(camera.link.has_packets, camera.link.packets_resent)},
        {"missing", known(camera.link.has_packets, camera.link.packets_missing)},
        {"frames_missing_packets", camera.link.frames_missing_packets},
        {"triggers_merged",
         known(camera.link.counts_merged_triggers, camera.link.triggers_merged)}};
  }
  return {{"resent", known(link.has_packets, link.packets_resent)},
          {"missing", known(link.has_packets, link.packets_missing)},
          {"frames_missing_packets", link.frames_missing_packets},
          {"triggers_merged", known(link.counts_merged_triggers, link.triggers_merged)},
          {"cameras", cameras}};
}

}  // namespace fieldrig::daemon
