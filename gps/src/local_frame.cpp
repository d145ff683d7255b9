#include "fieldrig/gps/local_frame.h"

#include <GeographicLib/Geodesic.hpp>
#include <cmath>
#include <numbers>

namespace fieldrig::gps {

LocalFrame::LocalFrame(double anchor_latitude_deg, double anchor_longitude_deg)
    : cartesian_(anchor_latitude_deg, anchor_longitude_deg, 0.0) {}

EnuPoint LocalFrame::toLocal(double latitude_deg, double longitude_deg) const {
  double east = 0, north = 0, up = 0;
  cartesian_.Forward(latitude_deg, longitude_deg, 0.0, east, north, up);
  return {east, north};
}

GeodeticPoint LocalFrame::toGeodetic(const EnuPoint& point) const {
  // The tangent plane's "up" at the point is not zero away from the anchor; projecting back
  // with up = 0 lands on the ellipsoid within micrometres over a field's extent.
  double latitude = 0, longitude = 0, height = 0;
  cartesian_.Reverse(point.east_m, point.north_m, 0.0, latitude, longitude, height);
  return {latitude, longitude};
}

double geodesicDistanceMetres(const GeodeticPoint& a, const GeodeticPoint& b) {
  double metres = 0;
  GeographicLib::Geodesic::WGS84().Inverse(a.latitude_deg, a.longitude_deg, b.latitude_deg,
                                           b.longitude_deg, metres);
  return metres;
}

double bearingDegrees(double east, double north) {
  double degrees = std::atan2(east, north) * 180.0 / std::numbers::pi;
  if (degrees < 0)
    degrees += 360.0;
  if (degrees >= 360.0)
    degrees -= 360.0;
  return degrees;
}

}  // namespace fieldrig::gps
