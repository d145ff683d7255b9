// The stem measurement page of `fieldrig stem-ui`: a static page (page.html, embedded at build
// time) that browses recorded sessions' FrameSets and heads, shows the left and right images,
// and talks to this JSON API:
//   GET    /api/sessions                                  sessions, their sets and heads
//   GET    /api/sessions/S/sets/I/HEAD/{left,right}.png   a frame as grey PNG
//   POST   /api/sessions/S/measure        {set, head, points:[8]}          measure only
//   POST   /api/sessions/S/measurements   {set, head, label, points:[8]}   measure and save
//   GET    /api/sessions/S/measurements   saved rows and mean/SD per stem
//   DELETE /api/sessions/S/measurements/last                               undo the last save
//   GET    /api/sessions/S/measurements.csv                                 export
// Bad requests get 4xx with {"error": "…"}: unknown session/set/head (404), path traversal,
// malformed JSON or numbers (400), a measurement that cannot be saved (422).
//
// Thread contract: thread-safe; handle() runs on the server's connection threads, and one mutex
// serialises the API (the measurers and the CSV files).
#pragma once

#include <filesystem>
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "fieldrig/core/result.h"
#include "fieldrig/recording/session_reader.h"
#include "fieldrig/stem/stem_measurer.h"
#include "stem_page/route_table.h"

namespace fieldrig::stem_page {

struct StemPageOptions {
  std::vector<std::string> sessions;  // session folders
  std::string calib;                  // the rig's calibration folder; empty: the sessions' own
  std::string out;                    // one CSV for all; empty: SESSION/stem_measurements.csv
};

class StemPage {
 public:
  // Opens every session; the error names the one that cannot be opened.
  static core::Result<std::unique_ptr<StemPage>> open(StemPageOptions options);

  HttpReply handle(const HttpRequest& request) const { return routes_.dispatch(request); }

 private:
  struct Session {
    std::string name;
    std::unique_ptr<recording::SessionReader> reader;
    std::filesystem::path csv;
  };

  explicit StemPage(StemPageOptions options);
  Session* findSession(const std::string& name);
  Session& session(const PathParams& params);
  stereo::StereoCalibration calibration(const Session& s, const std::string& head) const;
  const stem::StemMeasurer& measurer(const Session& s, const recording::IndexedSet& set,
                                     const std::string& head);
  nlohmann::ordered_json measurementsJson(const Session& s) const;

  // The API's handlers, each called with mutex_ held (locked()).
  using ApiHandler = HttpReply (StemPage::*)(const PathParams&, const HttpRequest&);
  Route::Handler locked(ApiHandler handler);
  HttpReply listSessions(const PathParams& params, const HttpRequest& request);
  HttpReply frameImage(const PathParams& params, const HttpRequest& request);
  HttpReply measure(const PathParams& params, const HttpRequest& request);
  HttpReply measurements(const PathParams& params, const HttpRequest& request);
  HttpReply saveMeasurement(const PathParams& params, const HttpRequest& request);
  HttpReply removeLastMeasurement(const PathParams& params, const HttpRequest& request);
  HttpReply exportCsv(const PathParams& params, const HttpRequest& request);
  static HttpReply page();

  StemPageOptions options_;
  std::vector<Session> sessions_;
  RouteTable routes_;
  std::mutex mutex_;  // held by every API handler: guards measurers_ and the CSV files
  // Measurers (decoded images + calibration) of recently used pairs, most recent first.
  std::list<std::pair<std::string, stem::StemMeasurer>> measurers_;
};

}  // namespace fieldrig::stem_page
