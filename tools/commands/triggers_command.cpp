#include "commands/commands.h"

namespace fieldrig::tools {
void registerTriggersCommand(CLI::App&, int&) {}
}  // namespace fieldrig::tools
