// The dc1394 driver's pure parts: the settings derived from a configuration (including real ROS
// camera1394 parameter files), and the pairing of frames with triggers.
#include "fieldrig/drivers/dc1394/dc1394_settings.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <string>

#include "fieldrig/drivers/dc1394/trigger_matcher.h"

namespace fieldrig::drivers {
namespace {

const std::string kCamera1394Dir = std::string(FIELDRIG_SHARED_DATA_DIR) + "/camera/camera1394/";

// What a ROS camera1394 parameter file says, in fieldrig's terms: the GUID is the id, the Bayer
// pattern the pixel format, the video mode and ISO speed driver options.
CameraConfig configFromCamera1394(const YAML::Node& yaml) {
  CameraConfig config;
  config.id = yaml["guid"].as<std::string>();
  config.options["video_mode"] = yaml["video_mode"].as<std::string>();
  config.options["iso_speed"] = yaml["iso_speed"].as<std::string>();
  if (yaml["bayer_pattern"]) {
    const auto format = pixelFormatFromBayerPattern(yaml["bayer_pattern"].as<std::string>());
    if (format)
      config.format = *format;
  }
  return config;
}

TEST(Dc1394Settings, SonyFormat7FileMapsToDriverSettings) {
  const YAML::Node yaml = YAML::LoadFile(kCamera1394Dir + "sony_format7.yaml");
  const auto settings = dc1394SettingsFromConfig(configFromCamera1394(yaml));
  ASSERT_TRUE(settings.ok()) << settings.error().message;
  ASSERT_TRUE(settings->guid.has_value());
  EXPECT_EQ(*settings->guid, 0x0800461000821fa2u);
  EXPECT_EQ(formatGuid(*settings->guid), "0800461000821fa2");
  EXPECT_EQ(settings->format7_mode, 0u);
  EXPECT_EQ(settings->iso_speed_mbps, 800u);
  EXPECT_TRUE(settings->operation_mode_1394b);
  EXPECT_EQ(settings->bus.name, "S800");
  EXPECT_EQ(settings->bus.bytes_per_cycle, 8000u);
  EXPECT_EQ(settings->format, core::PixelFormat::kBayerGB8);  // bayer_pattern: gbrg
  EXPECT_EQ(settings->width, 1624u);   // CameraConfig's full Grasshopper frame (the file's ROI
  EXPECT_EQ(settings->height, 1224u);  // lines are commented out)
  EXPECT_EQ(settings->trigger, TriggerSource::kSoftware);
  EXPECT_EQ(settings->broadcast, Dc1394Broadcast::kOff);
  // The plan the driver would apply for six such cameras at the default 5 Hz.
  const auto plan = requireIsoPlan(dc1394IsoRequest(*settings, 4, 8192));
  ASSERT_TRUE(plan.ok()) << plan.error().message;
  EXPECT_EQ(plan->packet_bytes, 1332u);
}

TEST(Dc1394Settings, UnibrainFileIsRefusedAsNotFormat7) {
  // A Fire-i in 640x480_yuv411 at S400: a fixed IIDC mode this driver does not drive.
  const YAML::Node yaml = YAML::LoadFile(kCamera1394Dir + "unibrain.yaml");
  const CameraConfig config = configFromCamera1394(yaml);
  EXPECT_EQ(config.id, "08144361026320a0");
  const auto settings = dc1394SettingsFromConfig(config);
  ASSERT_FALSE(settings.ok());
  EXPECT_NE(settings.error().message.find("'640x480_yuv411' is not a Format7 mode"),
            std::string::npos)
      << settings.error().message;
  // The same camera in a Format7 mode at its S400 speed: legacy operation mode, 4,096 bytes.
  CameraConfig format7 = config;
  format7.options["video_mode"] = "format7_mode1";
  const auto s400 = dc1394SettingsFromConfig(format7);
  ASSERT_TRUE(s400.ok()) << s400.error().message;
  EXPECT_EQ(s400->format7_mode, 1u);
  EXPECT_FALSE(s400->operation_mode_1394b);
  EXPECT_EQ(s400->bus.bytes_per_cycle, 4096u);
}

TEST(Dc1394Settings, DefaultsAndOptions) {
  CameraConfig config;
  config.id = "first";
  config.trigger = TriggerSource::kSoftware;
  config.options = {{"camera_index", "3"},         {"bus_cameras", "2"},
                    {"rate_hz", "12.5"},           {"dma_buffers", "16"},
                    {"trigger_broadcast", "send"}, {"bus_bytes_per_cycle", "10000"}};
  const auto s = dc1394SettingsFromConfig(config);
  ASSERT_TRUE(s.ok()) << s.error().message;
  EXPECT_FALSE(s->guid.has_value());
  EXPECT_EQ(s->camera_index, 3u);
  EXPECT_EQ(s->bus_cameras, 2u);
  EXPECT_DOUBLE_EQ(s->rate_hz, 12.5);
  EXPECT_EQ(s->dma_buffers, 16u);
  EXPECT_EQ(s->broadcast, Dc1394Broadcast::kSend);
  EXPECT_EQ(s->bus.bytes_per_cycle, 10000u);
  EXPECT_EQ(parseGuid("0x0800461000821FA2"), 0x0800461000821fa2u);
}

TEST(Dc1394Settings, BadConfigurationsNameTheProblem) {
  auto message = [](CameraConfig config) {
    const auto s = dc1394SettingsFromConfig(config);
    return s.ok() ? std::string("(accepted)") : s.error().message;
  };
  CameraConfig good;
  good.id = "0800461000821fa2";

  CameraConfig c = good;
  c.id = "sony";
  EXPECT_NE(message(c).find("GUID in hex"), std::string::npos) << message(c);
  c = good;
  c.options["exposure"] = "1";
  EXPECT_NE(message(c).find("unknown option 'exposure'"), std::string::npos) << message(c);
  c = good;
  c.options["iso_speed"] = "1600";
  EXPECT_NE(message(c).find("iso_speed 1600 is not supported"), std::string::npos);
  c = good;
  c.options["rate_hz"] = "fast";
  EXPECT_NE(message(c).find("option 'rate_hz': 'fast' is not a number"), std::string::npos);
  c = good;
  c.options["dma_buffers"] = "1";
  EXPECT_NE(message(c).find("dma_buffers must be at least 2"), std::string::npos);
  c = good;
  c.trigger = TriggerSource::kExternal;
  c.options["trigger_broadcast"] = "send";
  EXPECT_NE(message(c).find("needs the software trigger"), std::string::npos);
  c = good;
  c.format = core::PixelFormat::kMono8;
  EXPECT_NE(message(c).find("Mono8"), std::string::npos);
  c = good;
  c.options["video_mode"] = "format7_mode8";
  EXPECT_NE(message(c).find("not a Format7 mode"), std::string::npos);
}

TEST(TriggerMatcher, PairsFramesWithTriggersInOrder) {
  TriggerMatcher matcher(8, 250'000);  // frames within 250 ms of their trigger
  ASSERT_TRUE(matcher.addTrigger(10, 1'000'000));
  ASSERT_TRUE(matcher.addTrigger(11, 1'200'000));
  // Frame of trigger 10 finishes 190 ms later, while 11 is already pending.
  auto m = matcher.matchFrame(1'190'000);
  EXPECT_EQ(m.trigger_id, 10u);
  EXPECT_EQ(m.missed, 0u);
  m = matcher.matchFrame(1'390'000);
  EXPECT_EQ(m.trigger_id, 11u);
  EXPECT_EQ(matcher.pending(), 0u);
}

TEST(TriggerMatcher, AMissedTriggerDoesNotShiftLaterFrames) {
  TriggerMatcher matcher(8, 250'000);
  matcher.addTrigger(1, 0);
  matcher.addTrigger(2, 400'000);  // the camera never answers trigger 1
  const auto m = matcher.matchFrame(590'000);
  EXPECT_EQ(m.trigger_id, 2u);
  EXPECT_EQ(m.missed, 1u);
}

TEST(TriggerMatcher, AFrameBeforeAnyTriggerIsUnexpected) {
  TriggerMatcher matcher(8, 250'000);
  EXPECT_FALSE(matcher.matchFrame(100).trigger_id.has_value());
  matcher.addTrigger(5, 1'000);
  EXPECT_FALSE(matcher.matchFrame(500).trigger_id.has_value());  // finished before the trigger
  EXPECT_EQ(matcher.matchFrame(2'000).trigger_id, 5u);
}

TEST(TriggerMatcher, ExpiresUnansweredTriggersAndIsBounded) {
  TriggerMatcher matcher(2, 1'000);
  EXPECT_TRUE(matcher.addTrigger(1, 0));
  EXPECT_TRUE(matcher.addTrigger(2, 10));
  EXPECT_FALSE(matcher.addTrigger(3, 20));  // full
  EXPECT_EQ(matcher.expire(1'005), 1u);     // trigger 1 only
  EXPECT_EQ(matcher.pending(), 1u);
  EXPECT_TRUE(matcher.addTrigger(3, 20));
  EXPECT_EQ(matcher.expire(5'000), 2u);
  EXPECT_EQ(matcher.pending(), 0u);
}

}  // namespace
}  // namespace fieldrig::drivers
