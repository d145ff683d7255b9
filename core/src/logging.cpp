#include "fieldrig/core/logging.h"

#include <spdlog/sinks/rotating_file_sink.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <memory>
#include <vector>

namespace fieldrig::core {

void setupLogging(std::string_view level, const std::string& log_file) {
  std::vector<spdlog::sink_ptr> sinks;
  sinks.push_back(std::make_shared<spdlog::sinks::stderr_color_sink_mt>());
  if (!log_file.empty()) {
    constexpr std::size_t kMaxFileBytes = 20 * 1024 * 1024;
    constexpr std::size_t kKeptFiles = 5;
    sinks.push_back(std::make_shared<spdlog::sinks::rotating_file_sink_mt>(log_file, kMaxFileBytes,
                                                                           kKeptFiles));
  }
  auto logger = std::make_shared<spdlog::logger>("fieldrig", sinks.begin(), sinks.end());
  logger->set_level(spdlog::level::from_str(std::string(level)));
  logger->set_pattern("%Y-%m-%dT%H:%M:%S.%e %^%l%$ %v");
  spdlog::set_default_logger(std::move(logger));
}

}  // namespace fieldrig::core
