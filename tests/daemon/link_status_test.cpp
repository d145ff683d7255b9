// The status's "packets": totals over the cameras whose transport has packets, per camera by
// name, and null (not known) where a camera has none; hand-made summaries, no daemon.
#include "fieldrig/daemon/link_status.h"

#include <gtest/gtest.h>

namespace fieldrig::daemon {
namespace {

drivers::CameraLinkStats gige(std::uint64_t resent, std::uint64_t missing, std::uint64_t damaged) {
  drivers::CameraLinkStats link;
  link.has_packets = true;
  link.packets_resent = resent;
  link.packets_missing = missing;
  link.frames_missing_packets = damaged;
  link.counts_merged_triggers = true;
  link.triggers_merged = damaged + 1;
  return link;
}

TEST(LinkStatus, TotalsCountOnlyCamerasWithPacketsAndOthersAreNull) {
  LinkSummary summary;
  summary.has_packets = true;
  summary.packets_resent = 7 + 2;
  summary.packets_missing = 3 + 0;
  summary.frames_missing_packets = 1 + 0;
  summary.counts_merged_triggers = true;
  summary.triggers_merged = 2 + 1;
  summary.cameras = {{"bottom_left", gige(7, 3, 1)},
                     {"bottom_right", gige(2, 0, 0)},
                     {"middle_left", drivers::CameraLinkStats{}}};
  const auto json = linkStatusJson(summary);
  EXPECT_EQ(json.at("resent"), 9);
  EXPECT_EQ(json.at("missing"), 3);
  EXPECT_EQ(json.at("frames_missing_packets"), 1);
  const auto& cameras = json.at("cameras");
  ASSERT_EQ(cameras.size(), 3u);
  EXPECT_EQ(cameras.at("bottom_left").at("resent"), 7);
  EXPECT_EQ(cameras.at("bottom_left").at("missing"), 3);
  EXPECT_EQ(cameras.at("bottom_left").at("frames_missing_packets"), 1);
  EXPECT_EQ(cameras.at("bottom_right").at("resent"), 2);
  EXPECT_EQ(json.at("triggers_merged"), 3);
  EXPECT_EQ(cameras.at("bottom_left").at("triggers_merged"), 2);
  EXPECT_TRUE(cameras.at("middle_left").at("triggers_merged").is_null());
  EXPECT_TRUE(cameras.at("middle_left").at("resent").is_null());
  EXPECT_TRUE(cameras.at("middle_left").at("missing").is_null());
  // In the rig's order, as the page lists cameras.
  EXPECT_EQ(cameras.begin().key(), "bottom_left");
}

TEST(LinkStatus, NoCameraWithPacketsGivesNullTotals) {
  LinkSummary summary;
  summary.cameras = {{"camera0", drivers::CameraLinkStats{}}};
  const auto json = linkStatusJson(summary);
  EXPECT_TRUE(json.at("resent").is_null());
  EXPECT_TRUE(json.at("missing").is_null());
  EXPECT_EQ(json.at("frames_missing_packets"), 0);
  EXPECT_TRUE(json.at("triggers_merged").is_null());
}

}  // namespace
}  // namespace fieldrig::daemon
