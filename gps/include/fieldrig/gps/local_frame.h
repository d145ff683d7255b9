// A local tangent plane (east, north in metres) anchored at one point, via GeographicLib.
// Thread-compatible; const methods may be called concurrently.
//
// One frame is anchored per imaging-location map, so all distances the trigger planner and the
// map tools compute are plain 2-D vector arithmetic in metres.
#pragma once

#include <GeographicLib/LocalCartesian.hpp>

namespace fieldrig::gps {

struct EnuPoint {
  double east_m = 0;
  double north_m = 0;
};

struct GeodeticPoint {
  double latitude_deg = 0;
  double longitude_deg = 0;
};

class LocalFrame {
 public:
  LocalFrame(double anchor_latitude_deg, double anchor_longitude_deg);

  EnuPoint toLocal(double latitude_deg, double longitude_deg) const;
  GeodeticPoint toGeodetic(const EnuPoint& point) const;

  GeodeticPoint anchor() const {
    return {cartesian_.LatitudeOrigin(), cartesian_.LongitudeOrigin()};
  }

 private:
  GeographicLib::LocalCartesian cartesian_;
};

// The WGS84 geodesic distance between two points, metres (GeographicLib).
double geodesicDistanceMetres(const GeodeticPoint& a, const GeodeticPoint& b);

// Degrees true (clockwise from north) of an east/north direction, in [0, 360).
double bearingDegrees(double east, double north);

}  // namespace fieldrig::gps
