#include "fieldrig/drivers/dc1394/iso_bandwidth.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace fieldrig::drivers {
namespace {

// "23856" → "23,856": the refusal is read by an operator comparing it with a data sheet.
// Built forward by push_back, not insert(i, ","): GCC 12 -O3 gives a false-positive -Wrestrict.
std::string groupDigits(std::uint64_t value) {
  const std::string digits = std::to_string(value);
  std::string grouped;
  for (std::size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0)
      grouped.push_back(',');
    grouped.push_back(digits[i]);
  }
  return grouped;
}

// "10" for a whole rate, "7.5" or "5.36" otherwise (two decimals at most, trailing zeros cut).
std::string formatRate(double hz) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2f", hz);
  std::string s = text;
  while (!s.empty() && s.back() == '0')
    s.pop_back();
  if (!s.empty() && s.back() == '.')
    s.pop_back();
  return s;
}

std::string pixelName(std::uint32_t bytes_per_pixel) {
  return bytes_per_pixel == 1 ? "RAW8" : std::to_string(bytes_per_pixel * 8) + "-bit";
}

std::string describe(const IsoRequest& r) {
  return std::to_string(r.cameras) + (r.cameras == 1 ? " camera × " : " cameras × ") +
         std::to_string(r.width) + "×" + std::to_string(r.height) + " " +
         pixelName(r.bytes_per_pixel) + " at " + formatRate(r.rate_hz) + " Hz";
}

std::uint64_t ceilDiv(std::uint64_t a, std::uint64_t b) {
  return (a + b - 1) / b;
}

}  // namespace

core::Result<IsoPlan> planIsoBandwidth(const IsoRequest& r) {
  if (r.cameras == 0)
    return core::Error{"iso bandwidth plan: no cameras"};
  if (r.width == 0 || r.height == 0 || r.bytes_per_pixel == 0)
    return core::Error{"iso bandwidth plan: empty image (width, height and bytes per pixel > 0)"};
  if (r.unit_bytes == 0)
    return core::Error{"iso bandwidth plan: the Format7 unit size is 0"};
  if (r.max_packet_bytes != 0 && r.max_packet_bytes < r.unit_bytes) {
    return core::Error{"iso bandwidth plan: the camera's maximum packet (" +
                       std::to_string(r.max_packet_bytes) + " bytes) is below its unit (" +
                       std::to_string(r.unit_bytes) + " bytes)"};
  }
  if (!(r.rate_hz > 0) || !std::isfinite(r.rate_hz))
    return core::Error{"iso bandwidth plan: the trigger rate must be positive"};
  if (r.bus.bytes_per_cycle == 0)
    return core::Error{"iso bandwidth plan: the bus " + r.bus.name + " has no budget"};

  IsoPlan plan;
  plan.frame_bytes = std::uint64_t{r.width} * r.height * r.bytes_per_pixel;

  // The largest packet a camera may use: its Format7 maximum and the bus budget, in whole units.
  const std::uint32_t camera_cap = r.max_packet_bytes == 0
                                       ? r.bus.bytes_per_cycle
                                       : std::min(r.max_packet_bytes, r.bus.bytes_per_cycle);
  const std::uint32_t camera_cap_units = camera_cap / r.unit_bytes * r.unit_bytes;
  const std::uint32_t share = r.bus.bytes_per_cycle / r.cameras;
  plan.packet_bytes = std::min(share, camera_cap) / r.unit_bytes * r.unit_bytes;

  // The wanted rate leaves floor(8000 / rate) cycles per frame; the frame must fit in them.
  // (The epsilon keeps 8000 / 10 from landing just below 800 through rounding.)
  const auto cycles_per_period =
      static_cast<std::uint64_t>(std::floor(kIsoCyclesPerSecond / r.rate_hz + 1e-9));
  if (cycles_per_period == 0) {
    plan.needed_packet_bytes = 0;
  } else {
    const std::uint64_t needed =
        ceilDiv(ceilDiv(plan.frame_bytes, cycles_per_period), r.unit_bytes) * r.unit_bytes;
    plan.needed_packet_bytes =
        static_cast<std::uint32_t>(std::min<std::uint64_t>(needed, UINT32_MAX));
    plan.needed_bytes_per_cycle =
        static_cast<std::uint32_t>(std::min<std::uint64_t>(needed * r.cameras, UINT32_MAX));
  }

  if (plan.packet_bytes > 0) {
    plan.packets_per_frame =
        static_cast<std::uint32_t>(ceilDiv(plan.frame_bytes, plan.packet_bytes));
    plan.max_rate_hz = kIsoCyclesPerSecond / plan.packets_per_frame;
    plan.bytes_per_cycle = plan.packet_bytes * r.cameras;
  }
  plan.max_fitting_rate_hz = plan.max_rate_hz;

  const std::string what = describe(r);
  const std::string at_most = " (" + formatRate(plan.max_rate_hz) + " Hz at most)";
  if (plan.packet_bytes == 0) {
    plan.message = what + ": each camera's share of " + r.bus.name + " (" + groupDigits(share) +
                   " bytes per 125 µs cycle) is below its packet unit of " +
                   std::to_string(r.unit_bytes) + " bytes";
  } else if (cycles_per_period == 0) {
    plan.message = what + ": faster than one frame per 125 µs cycle" + at_most;
  } else if (plan.needed_packet_bytes > camera_cap_units) {
    plan.message = what + (r.cameras == 1 ? " needs " : " need ") +
                   groupDigits(plan.needed_packet_bytes) +
                   "-byte packets per 125 µs cycle; the camera allows " +
                   groupDigits(camera_cap_units) + at_most;
  } else if (plan.needed_packet_bytes > plan.packet_bytes) {
    plan.message = what + (r.cameras == 1 ? " needs " : " need ") +
                   groupDigits(plan.needed_bytes_per_cycle) + " bytes per 125 µs cycle; " +
                   r.bus.name + " allows " + groupDigits(r.bus.bytes_per_cycle) + at_most;
  }
  plan.fits = plan.message.empty();
  return plan;
}

core::Result<IsoPlan> requireIsoPlan(const IsoRequest& request) {
  auto plan = planIsoBandwidth(request);
  if (plan.ok() && !plan->fits)
    return core::Error{plan->message};
  return plan;
}

}  // namespace fieldrig::drivers
