#include "commands/commands.h"

namespace fieldrig::tools {
void registerMapCommand(CLI::App&, int&) {}
}  // namespace fieldrig::tools
