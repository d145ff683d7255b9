// The Aravis driver: GigE Vision and USB3 Vision cameras through Aravis 0.8, the rig's upgrade
// path from the 1394b Grasshoppers. Built only when pkg-config finds aravis-0.8; Aravis' own
// headers stay inside drivers/aravis (this header names none of its types).
//
// CameraConfig::id is what arv_camera_new takes: a device id ("Basler-21234567"), an IP address
// ("192.168.1.20", "127.0.0.1" for arv-fake-gv-camera on the loopback) or "Fake_N", which also
// enables Aravis' in-process fake interface (tests and demos without a network).
//
// CameraConfig::options:
//   camera_index=N        the rig index written into each frame's metadata (default 0)
//   offset_x=X offset_y=Y the ROI's origin on the sensor (default 0, 0)
//   trigger_line=LineK    the TriggerSource for TriggerSource::kExternal (default Line0)
//   buffers=N             Aravis stream buffers allocated at start (default 8)
//   genicam_pixel_format=NAME  the PixelFormat entry to request when the camera names the 8-bit
//                         format differently from fieldrig's GenICam name; frames keep `format`
//   packet_size=BYTES     GigE Vision stream packet size (default: the camera's)
//   packet_resend=never|always  GigE Vision packet resend requests (default: Aravis' default)
//   min_trigger_interval_us=US  the shortest time between the acknowledgement of one software
//                         trigger and the next command (default: one period of the camera's
//                         AcquisitionFrameRate, 0 when it has none; 0 turns pacing off)
//
// Triggers and frames: trigger() only queues the id (lock-free) and wakes the driver's trigger
// thread, which issues the software trigger (a GVCP register write, a network round trip) and
// notes, on the host's real-time clock, when it sent the command and when the camera
// acknowledged it. The camera's frame id tells how many frames it sent that never arrived, and
// those triggers are counted lost rather than shifting the ids of later frames. A whole frame
// whose device timestamp is on the host's clock (a camera synchronised by PTP, as the host is;
// arv-fake-gv-camera stamps with the host's clock) is matched by time: it answers the oldest
// outstanding trigger sent before its exposure, and the later ones the camera had already
// received by then (acknowledged before the exposure) were merged into it by the camera and are
// counted lost (triggers_merged). A trigger sent before the exposure but acknowledged after it
// may have come just before or just after: it stays outstanding, and the next frame settles it:
// if that frame came later than the camera has ever taken to answer a trigger, the trigger was
// merged; otherwise it is that frame's trigger (the host's stamps bracket the camera's receipt;
// guessing inside that bracket failed when a slow host widened it). A frame exposed before every
// outstanding trigger was sent answers none and is counted unsolicited. So a merge
// costs its own trigger's frame, never the trigger ids of the frames after it. Other frames
// (another clock, damaged frames whose stamp may be stale) are matched in order. Frames that arrive
// with no trigger outstanding (a free-running camera) are returned to the stream uncounted as
// frames and counted as unsolicited. With an external trigger, trigger() refuses (false) and frames
// are numbered 1, 2, … in arrival order, gaps included.
//
// Pacing: a camera takes at most one trigger per frame period; a second command inside the same
// period is merged into the first (arv-fake-gv-camera serves one per 40 ms) and the frame it never
// sends carries no frame-id gap: matched by time the merged trigger is counted lost, matched in
// order every later frame would take the trigger before its own; either way it has no frame.
// Scheduling delays on a busy host bunch triggers that were sent evenly, so the trigger worker
// holds a command back until min_trigger_interval_us has passed since the previous one was
// acknowledged; trigger() itself still never waits.
//
// Thread contract: configure/start/stop on the owner thread; trigger() on one thread (the
// trigger thread), never blocks; stats() and linkStats() from any thread (a mutex the frame path
// never takes keeps the stream alive while they read it). The FrameSink runs on Aravis' stream
// thread.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include "fieldrig/core/spsc_queue.h"
#include "fieldrig/drivers/camera.h"

namespace fieldrig::drivers {

// What went wrong on the way, for the run summary and health. A snapshot.
struct AravisStats {
  std::uint64_t triggers_accepted = 0;  // trigger() returned true
  std::uint64_t triggers_refused = 0;   // not started, external trigger, or queue full
  std::uint64_t triggers_failed = 0;    // never sent (stop came first) or the command failed
  std::uint64_t frames_delivered = 0;   // handed to the sink, whatever their status
  std::uint64_t frames_corrupt = 0;     // delivered with status kCorrupt (sum of the reasons below)
  std::uint64_t frames_dropped = 0;     // delivered as kDropped: the frame pool was empty
  std::uint64_t frames_lost = 0;        // triggered, never delivered (frame-id gap, or stop)
  std::uint64_t frames_unsolicited = 0;  // arrived with no trigger outstanding; not delivered
  std::uint64_t triggers_paced = 0;      // commands held back to keep the minimum interval
  // Triggers the camera merged into an earlier trigger's exposure (also in frames_lost).
  std::uint64_t triggers_merged = 0;
  std::uint64_t frames_matched_by_time = 0;  // by device timestamp; the others by frame order
  std::int64_t min_trigger_interval_us = 0;  // the pacing in force (configure's result)
  // The shortest time from one command's acknowledgement to the next command, -1 before two.
  std::int64_t shortest_trigger_gap_us = -1;
  // Corrupt frames by Aravis buffer status.
  std::uint64_t status_timeout = 0;
  std::uint64_t status_missing_packets = 0;
  std::uint64_t status_size_mismatch = 0;  // includes a payload smaller than the ROI
  std::uint64_t status_other = 0;
  // Aravis' own stream counters (arv_stream_get_statistics), as of the last stop() or now.
  std::uint64_t stream_completed = 0;
  std::uint64_t stream_failures = 0;
  std::uint64_t stream_underruns = 0;  // a frame came with no free Aravis buffer
  // GigE Vision only (arv_gv_stream_get_statistics): packets that came back after a resend
  // request, and packets of failed frames that never came.
  std::uint64_t packets_resent = 0;
  std::uint64_t packets_missing = 0;
};

class AravisCamera final : public Camera {
 public:
  AravisCamera();
  ~AravisCamera() override;
  AravisCamera(const AravisCamera&) = delete;
  AravisCamera& operator=(const AravisCamera&) = delete;

  std::string driverName() const override { return "aravis"; }
  core::Result<void> configure(const CameraConfig& config) override;
  core::Result<void> start(core::FramePool& pool, FrameSink sink) override;
  void stop() override;
  bool trigger(std::uint64_t trigger_id) override;

  AravisStats stats() const;
  // packets_resent and packets_missing of a GigE Vision stream, and the frames marked for missing
  // packets; has_packets is false for a USB3 Vision or in-process fake camera.
  CameraLinkStats linkStats() const override;

 private:
  struct Vendor;  // the Aravis objects; defined where arv.h is included

  void runTriggers();
  void issueTrigger(std::uint64_t trigger_id);
  // Stream thread: one finished Aravis buffer to one Frame for the sink.
  void deliver(const void* data, std::size_t size, int arv_status, std::uint64_t frame_id,
               std::uint64_t device_timestamp_ns);
  // Stream thread: the trigger id for the next frame, after `gap` - 1 frames that never came;
  // false when none is outstanding.
  // `exposed_ns`: the frame's device timestamp on the host's real-time clock, or nullopt when it
  // is not (then frames are matched in order).
  bool matchTrigger(std::uint64_t gap, std::optional<std::int64_t> exposed_ns,
                    std::uint64_t& trigger_id);
  std::uint64_t outstandingTriggers() const;  // owner thread, after the stream has stopped
  friend struct AravisCallbacks;

  // Issued trigger ids, in order, for the stream thread to match frames against. A slot of a
  // trigger whose command failed holds kFailedTrigger. Written by the trigger thread, read by the
  // stream thread; issued_ and consumed_ publish the positions.
  static constexpr std::size_t kIssuedRing = 1024;
  static constexpr std::uint64_t kFailedTrigger = ~std::uint64_t{0};

  CameraConfig config_;
  std::uint32_t camera_index_ = 0;
  std::uint32_t offset_x_ = 0;
  std::uint32_t offset_y_ = 0;
  std::uint32_t buffer_count_ = 8;
  std::chrono::microseconds min_trigger_interval_{0};
  std::unique_ptr<Vendor> vendor_;
  core::FramePool* pool_ = nullptr;
  FrameSink sink_;

  core::SpscQueue<std::uint64_t> triggers_{256};  // trigger thread → trigger worker
  std::atomic<std::uint32_t> wakeups_{0};         // bumped per trigger; the worker waits on it
  std::atomic<bool> running_{false};
  std::thread trigger_worker_;
  std::unique_ptr<std::atomic<std::uint64_t>[]> issued_ids_;  // kIssuedRing slots
  // Per slot, host real-time clock (ns): the command sent, and acknowledged (kNotAcked until then).
  std::unique_ptr<std::atomic<std::int64_t>[]> issued_sent_ns_;
  std::unique_ptr<std::atomic<std::int64_t>[]> issued_acked_ns_;
  static constexpr std::int64_t kNotAcked = std::numeric_limits<std::int64_t>::max();
  std::atomic<std::uint64_t> issued_{0};    // slots written (trigger worker)
  std::atomic<std::uint64_t> consumed_{0};  // slots matched or counted lost (stream thread)

  // Trigger worker only: when the previous command was acknowledged.
  std::chrono::steady_clock::time_point last_trigger_acked_{};

  // Stream thread only.
  bool have_frame_id_ = false;
  std::uint64_t last_frame_id_ = 0;
  std::uint64_t external_count_ = 0;
  // The exposure of the last frame matched by time (nullopt after one matched in order), and the
  // longest a trigger sent after the previous exposure took to be exposed (-1 before any).
  std::optional<std::int64_t> last_exposed_ns_;
  std::int64_t answer_latency_ns_ = -1;

  // Counters, each written by one thread, read by stats().
  std::atomic<std::uint64_t> accepted_{0}, refused_{0}, failed_{0}, delivered_{0}, corrupt_{0},
      dropped_{0}, lost_{0}, unsolicited_{0}, timeout_{0}, missing_packets_{0}, size_mismatch_{0},
      other_status_{0}, paced_{0}, merged_{0}, matched_by_time_{0};
  std::atomic<std::int64_t> shortest_gap_us_{-1};  // trigger worker
  std::atomic<bool> gv_device_{false};             // configure's camera speaks GigE Vision
  // Guards vendor_->stream's lifetime (start creates it, stop releases it) against readers on
  // other threads, and the totals the owner keeps from the last stop().
  mutable std::mutex stream_mutex_;
  std::uint64_t stream_completed_ = 0, stream_failures_ = 0, stream_underruns_ = 0,
                packets_resent_ = 0, packets_missing_ = 0;
};

}  // namespace fieldrig::drivers
