// A fake IEEE-1394 bus for the dc1394 driver's tests: a link-time stand-in for the libdc1394
// functions the driver calls (fake_libdc1394.cpp defines them; a test executable that links it
// gets the fake instead of the real library). One simulated Format7 camera per GUID; a software
// trigger (or a pulse on the external line) exposes a frame into the DMA ring at once.
//
// It records what the driver did to the bus (ISO resources taken and released, transmission,
// trigger writes) so that tests can check that every exit path gives the bus back, and it injects
// faults (capture setup or transmission refused, triggers that expose nothing, corrupt frames).
//
// Vendor-free on purpose: tests include this, never libdc1394's headers. Thread-safe: every field
// is read and written under `mutex`.
#pragma once

#include <cstdint>
#include <mutex>
#include <vector>

namespace fieldrig::drivers::testing {

struct FakeDc1394Bus {
  std::mutex mutex;

  // The bus, as the test sets it up.
  std::vector<std::uint64_t> guids;
  std::uint32_t max_width = 1624;
  std::uint32_t max_height = 1224;
  std::uint32_t unit_bytes = 4;
  std::uint32_t max_bytes = 8192;
  int color_filter = 0;  // 0 RGGB, 1 GBRG, 2 GRBG, 3 BGGR
  bool fail_capture_setup = false;
  bool fail_transmission = false;
  bool broadcast_supported = true;
  std::uint32_t triggers_to_ignore = 0;  // the next N triggers expose nothing
  bool corrupt_next = false;

  // What the driver did.
  int contexts_open = 0;
  int cameras_open = 0;
  int capture_setups = 0;
  int capture_stops = 0;
  int iso_release_alls = 0;
  bool capturing = false;
  bool transmitting = false;
  bool operation_mode_1394b = false;
  int iso_speed_mbps = 0;
  std::uint32_t packet_bytes = 0;
  bool trigger_on = false;
  bool software_source = false;
  int trigger_mode = -1;
  std::uint32_t dma_buffers = 0;
  int software_triggers = 0;
  int broadcast_triggers = 0;
  bool broadcast_left_on = false;
  float shutter_s = 0;
  float gain_db = 0;
};

// The process's fake bus; reset() puts every field back to its default.
FakeDc1394Bus& fakeDc1394Bus();
void resetFakeDc1394Bus();
// A pulse on the external trigger line of every camera whose source is TRIGGER_SOURCE_0.
void fakeDc1394Pulse();
// A frame that no trigger asked for (a free-running camera, a glitch on the line).
void fakeDc1394SpuriousFrame();

}  // namespace fieldrig::drivers::testing
