#include "fieldrig/gps/serial_trigger_chain.h"

#include <utility>

namespace fieldrig::gps {

core::Result<SerialTriggerChain> SerialTriggerChain::create(
    boost::asio::io_context& io, const LocationMap& map, SerialOptions serial,
    TriggerChainOptions triggers, LiveTriggerHandlers handlers,
    SerialNmeaSource::StatusHandler on_serial) {
  auto chain = LiveTriggerChain::create(io, map, triggers, std::move(handlers));
  if (!chain)
    return chain.error();
  LiveTriggerChain* feed = chain->get();
  auto source = SerialNmeaSource::create(
      io, std::move(serial),
      [feed](const Sentence& sentence, const core::ReceptionStamp& received) {
        feed->onSentence(sentence, received);
      },
      std::move(on_serial));
  if (!source)
    return source.error();
  return SerialTriggerChain(std::move(*chain), std::move(*source));
}

}  // namespace fieldrig::gps
