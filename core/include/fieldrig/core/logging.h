// Logging set-up: one place decides where spdlog writes and how loud it is.
#pragma once

#include <string>
#include <string_view>

namespace fieldrig::core {

// Installs the default logger: human-readable lines on stderr (stdout is kept for data such as
// JSON lines), optionally a rotating file as well. `level` is spdlog's name ("info", "debug"…).
void setupLogging(std::string_view level = "info", const std::string& log_file = {});

}  // namespace fieldrig::core
