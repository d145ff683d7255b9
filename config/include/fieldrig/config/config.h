// fieldrig's configuration: one YAML file (yaml-cpp) loaded into the components' own option
// structs, in one place. Every key is optional (the defaults are the structs' own); an unknown
// key, a value of the wrong type or out of range, a missing file, is an error that names the
// file, the line and the key path ("fieldrigd.yaml:12: gps.serial.baud: …").
//
// Relative paths in the file are taken relative to the file's folder, so a configuration and the
// map, calibration and session it names can travel together.
//
// Layout of the file (every section and key optional; the keys of the option structs are their
// field names; config/fieldrigd.yaml explains each key for a crew):
//   gps:        serial {device, baud, reopen_initial_ms, reopen_max_ms}, latency_s,
//               planner {cross_track_tolerance_m, heading_tolerance_deg, min_speed_mps, …
//               every gps::TriggerOptions field}
//   map:        the imaging-location map (CSV)
//   cameras:    driver, heads [bottom, middle, top], ids [one per camera in rig order: bottom_left,
//               bottom_right, middle_left, …; default for sim "0" … "5"], width, height,
//               pixel_format (GenICam name), exposure_us, gain_db, white_balance [blue, red],
//               trigger (software|external), frame_timeout_ms, max_skew_us, pool_sets,
//               options {driver-specific key: value, given to every camera}
//   calibration: the calibration folder (rig.yml + one folder per head)
//   recording:  dir, fsync (none|per_set|per_frame)
//   pipeline:   enabled, queue_sets, cloud {scale, min_depth_m, max_depth_m, edge_max_jump_px,
//               edge_keep_near_side},
//               matcher {…MatcherOptions; mode sgbm|hh|sgbm_3way|hh4},
//               traits {…TraitsOptions; outlier_method statistical|voxel_neighbours,
//               area_method depth_map|paper|none, camera_to_plot [[3 numbers] × 3]}
//   outputs:    dir (default RECORDING_DIR/results), csv, geojson, jsonl
//   status:     enabled, address, port
//   replay:     nmea (file or pty), realtime, session (recorded session the sim cameras replay)
//   log:        level (trace|debug|info|warn|error), file
// Relative paths: map, calibration, recording.dir, outputs.dir, replay.nmea, replay.session,
// log.file. cameras.rig.cameras always holds one CameraConfig per camera (2 × heads).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "fieldrig/cloud/cloud_options.h"
#include "fieldrig/config/traits_config.h"
#include "fieldrig/core/result.h"
#include "fieldrig/core/rig_layout.h"
#include "fieldrig/drivers/rig.h"
#include "fieldrig/gps/serial_nmea_source.h"
#include "fieldrig/gps/trigger_planner.h"
#include "fieldrig/recording/session_format.h"
#include "fieldrig/recording/session_writer.h"
#include "fieldrig/traits/plot_traits.h"

namespace fieldrig::config {

struct GpsConfig {
  gps::SerialOptions serial;          // device empty: no serial port configured
  gps::TriggerChainOptions triggers;  // planner options and latency_s
};

struct CamerasConfig {
  core::RigLayout layout;   // `heads`
  drivers::RigOptions rig;  // driver, cameras (ids and settings), timeouts, pool
};

struct RecordingConfig {
  std::filesystem::path dir;  // the session folder the daemon records into
  recording::WriterOptions writer;
};

struct PipelineConfig {
  bool enabled = true;         // live processing of the recorded sets
  std::size_t queue_sets = 2;  // sets waiting for processing; more are skipped (and counted)
  cloud::CloudOptions cloud;   // with its matcher (the file's pipeline.matcher)
  traits::TraitsOptions traits;
};

struct OutputsConfig {
  std::filesystem::path dir;  // empty: RECORDING_DIR/results
  bool csv = true;
  bool geojson = true;
  bool jsonl = true;
};

struct StatusConfig {
  bool enabled = true;
  std::string address = "127.0.0.1";
  std::uint16_t port = 8470;  // 0: any free port (the daemon logs the one it took)
};

struct ReplayConfig {
  std::filesystem::path nmea;     // NMEA capture (file) or a pty to read as the serial port
  bool realtime = false;          // a file is played at its own pace instead of virtual time
  std::filesystem::path session;  // the recorded session the sim cameras replay
};

struct LogConfig {
  std::string level = "info";
  std::filesystem::path file;  // empty: stderr (journald under systemd)
};

struct Config {
  std::filesystem::path source;  // the file it was loaded from (empty: defaults)
  GpsConfig gps;
  std::filesystem::path map;
  CamerasConfig cameras;
  std::filesystem::path calibration;
  RecordingConfig recording;
  PipelineConfig pipeline;
  OutputsConfig outputs;
  StatusConfig status;
  ReplayConfig replay;
  LogConfig log;
};

// The configuration of `file`. The error names the file, line and key path.
core::Result<Config> loadConfig(const std::filesystem::path& file);
// The same from text; `origin` names it in errors and relative paths resolve against `base_dir`.
core::Result<Config> parseConfig(const std::string& text, const std::string& origin,
                                 const std::filesystem::path& base_dir);

}  // namespace fieldrig::config
