#include "fieldrig/drivers/camera.h"

#ifdef FIELDRIG_HAVE_DC1394
#include "fieldrig/drivers/dc1394/dc1394_camera.h"
#endif
#ifdef FIELDRIG_HAVE_ARAVIS
#include "fieldrig/drivers/aravis/aravis_camera.h"
#endif

namespace fieldrig::drivers {

CameraRegistry& CameraRegistry::instance() {
  // Built-in drivers are added here rather than by static registrars in their own files: a
  // static library drops object files nothing refers to, registrars included. The sim driver
  // is not built in: drivers/ knows nothing of sim/, whose users add it (sim::addSimCamera).
  static CameraRegistry registry = [] {
    CameraRegistry r;
#ifdef FIELDRIG_HAVE_DC1394
    r.add("dc1394", [] { return makeDc1394Camera(); });
#endif
#ifdef FIELDRIG_HAVE_ARAVIS
    r.add("aravis", [] { return std::make_unique<AravisCamera>(); });
#endif
    return r;
  }();
  return registry;
}

void CameraRegistry::add(const std::string& name, Factory factory) {
  factories_[name] = std::move(factory);
}

core::Result<std::unique_ptr<Camera>> CameraRegistry::create(const std::string& name) const {
  const auto it = factories_.find(name);
  if (it == factories_.end()) {
    std::string known;
    for (const auto& [n, _] : factories_)
      known += (known.empty() ? "" : ", ") + n;
    return core::Error{"unknown camera driver '" + name + "' (this build has: " + known + ")"};
  }
  return it->second();
}

std::vector<std::string> CameraRegistry::names() const {
  std::vector<std::string> names;
  for (const auto& [name, _] : factories_)
    names.push_back(name);
  return names;
}

}  // namespace fieldrig::drivers
