#include "fieldrig/gps/fix_assembler.h"

namespace fieldrig::gps {
namespace {
constexpr auto kDay = std::chrono::days{1};
}

FixAssembler::FixAssembler(std::chrono::sys_days fallback_date) : fallback_date_(fallback_date) {}

std::optional<core::UtcTime> FixAssembler::dateTimeFor(core::Nanoseconds time_of_day) {
  if (!last_rmc_time_) {
    // No date from any RMC: a time of day far below the previous one is the next day (GGA-only
    // receivers cross 00:00 UTC in the evening of the Americas' working day).
    core::UtcTime time = core::UtcTime{fallback_date_} + time_of_day;
    if (last_dateless_time_ && *last_dateless_time_ - time > std::chrono::hours{12}) {
      fallback_date_ += kDay;
      time += kDay;
    }
    last_dateless_time_ = time;
    return time;
  }
  // The GGA belongs to the day whose instant is nearest the last RMC's: this handles a GGA just
  // after midnight following an RMC of the previous day, and the reverse.
  const auto rmc_day = std::chrono::floor<std::chrono::days>(*last_rmc_time_);
  core::UtcTime best = rmc_day + time_of_day;
  for (const auto candidate : {best - kDay, best + kDay}) {
    if (std::chrono::abs(candidate - *last_rmc_time_) < std::chrono::abs(best - *last_rmc_time_)) {
      best = candidate;
    }
  }
  return best;
}

std::optional<core::GpsFix> FixAssembler::add(const Sentence& sentence,
                                              const core::ReceptionStamp& received) {
  std::optional<core::UtcTime> time;
  bool has_date = false;
  if (sentence.kind == SentenceKind::kRmc) {
    if (!sentence.rmc.time_of_day)
      return std::nullopt;
    if (sentence.rmc.time) {
      time = sentence.rmc.time;
      has_date = true;
      last_rmc_time_ = time;
    } else {
      time = dateTimeFor(*sentence.rmc.time_of_day);
    }
  } else if (sentence.kind == SentenceKind::kGga) {
    if (!sentence.gga.time_of_day)
      return std::nullopt;
    time = dateTimeFor(*sentence.gga.time_of_day);
    has_date = last_rmc_time_.has_value();
  } else {
    return std::nullopt;
  }

  if (!epoch_ || epoch_->time != *time) {
    epoch_ = core::GpsFix{};
    epoch_->time = *time;
    epoch_has_rmc_ = epoch_has_gga_ = rmc_valid_ = gga_valid_ = false;
  }
  core::GpsFix& fix = *epoch_;
  fix.has_date = fix.has_date || has_date;
  fix.talker = std::string(sentence.talker);
  fix.received = received;
  if (sentence.kind == SentenceKind::kRmc) {
    const RmcData& rmc = sentence.rmc;
    epoch_has_rmc_ = true;
    rmc_valid_ = rmc.valid();
    if (rmc.latitude_deg && rmc.longitude_deg) {
      fix.latitude_deg = *rmc.latitude_deg;
      fix.longitude_deg = *rmc.longitude_deg;
    }
    fix.speed_mps = rmc.speed_mps;
    fix.course_deg = rmc.course_deg;
  } else {
    const GgaData& gga = sentence.gga;
    epoch_has_gga_ = true;
    gga_valid_ = gga.valid();
    if (gga.latitude_deg && gga.longitude_deg) {
      fix.latitude_deg = *gga.latitude_deg;
      fix.longitude_deg = *gga.longitude_deg;
    }
    fix.quality = static_cast<core::FixQuality>(gga.quality);
    fix.satellites = gga.satellites;
    fix.hdop = gga.hdop;
    fix.altitude_m = gga.altitude_m;
  }
  // Either sentence can veto: RMC status V or GGA quality 0 make the epoch invalid.
  fix.valid = (!epoch_has_rmc_ || rmc_valid_) && (!epoch_has_gga_ || gga_valid_);
  return fix;
}

}  // namespace fieldrig::gps
