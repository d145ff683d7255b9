// The isochronous bandwidth planner for IIDC (DCAM) cameras sharing one IEEE-1394 bus: how large a
// Format7 packet each camera may send per 125 µs bus cycle, and so how fast the rig can trigger.
//
// A Format7 camera sends one packet per bus cycle (8,000 cycles a second) while it transmits a
// frame; its packet size is a multiple of its unit size, at most its maximum. All cameras on the
// bus share each cycle, so the sum of their packet sizes must fit the bus's budget per cycle. A
// frame takes ceil(frame bytes / packet size) cycles, which bounds the frame rate.
//
// Pure: no I/O and no libdc1394, so the numbers are unit-tested and the driver only applies them.
// Thread-compatible (plain functions on values).
#pragma once

#include <cstdint>
#include <string>

#include "fieldrig/core/result.h"

namespace fieldrig::drivers {

inline constexpr double kIsoCyclesPerSecond = 8000;  // one isochronous cycle every 125 µs

// The bus speed and the isochronous bytes it can carry per cycle, for all cameras together.
struct IsoBus {
  std::string name = "S800";
  std::uint32_t bytes_per_cycle = 8000;

  // IEEE-1394b at 800 Mb/s: 8,000 bytes per cycle (IIDC limit used for the Grasshoppers' bus).
  static IsoBus s800() { return {"S800", 8000}; }
  // IEEE-1394a at 400 Mb/s: 4,096 bytes per cycle.
  static IsoBus s400() { return {"S400", 4096}; }
};

struct IsoRequest {
  std::uint32_t cameras = 6;
  std::uint32_t width = 1624;
  std::uint32_t height = 1224;
  std::uint32_t bytes_per_pixel = 1;  // RAW8 / Mono8
  double rate_hz = 5;                 // the wanted trigger rate
  IsoBus bus = IsoBus::s800();
  std::uint32_t unit_bytes = 4;        // the camera's Format7 packet granularity
  std::uint32_t max_packet_bytes = 0;  // the camera's Format7 maximum; 0 = the bus budget
};

struct IsoPlan {
  std::uint64_t frame_bytes = 0;             // one image
  std::uint32_t packet_bytes = 0;            // per camera per cycle (Format7 BYTE_PER_PACKET)
  std::uint32_t packets_per_frame = 0;       // cycles to transmit one frame
  double max_rate_hz = 0;                    // frames per second each camera can deliver
  std::uint32_t bytes_per_cycle = 0;         // all cameras at packet_bytes
  std::uint32_t needed_packet_bytes = 0;     // the smallest packet that reaches the wanted rate
  std::uint32_t needed_bytes_per_cycle = 0;  // all cameras at needed_packet_bytes
  double max_fitting_rate_hz = 0;            // the fastest rate this bus and these cameras allow
  bool fits = false;
  std::string message;  // why the plan does not fit, with the numbers; empty when it fits
};

// The plan for `request`: every camera gets the same packet, the largest multiple of unit_bytes
// within the camera's maximum and its equal share of the bus budget (the fastest transfer of each
// frame, so the least latency after a trigger). Fits when that packet reaches the wanted rate.
// An invalid request (no cameras, empty image, zero unit, maximum below the unit, rate not
// positive) is an error; a valid but impossible one is a plan with fits == false and a message.
core::Result<IsoPlan> planIsoBandwidth(const IsoRequest& request);

// As planIsoBandwidth, but an impossible plan is an error carrying its message, e.g.
// "6 cameras × 1624×1224 RAW8 at 10 Hz need 14,928 bytes per 125 µs cycle; S800 allows 8,000
// (5.36 Hz at most)".
core::Result<IsoPlan> requireIsoPlan(const IsoRequest& request);

}  // namespace fieldrig::drivers
