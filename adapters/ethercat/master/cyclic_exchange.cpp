#include "adapters/ethercat/master/cyclic_exchange.hpp"

#include <algorithm>

namespace drivegate::ethercat {

namespace {

// Tag: bits 16-31 the cycle's low 16 bits, 0-15 the image datagram index or kAlItem | slave.
constexpr std::uint32_t make_tag(std::uint64_t cycle, std::uint32_t item) noexcept {
  return (static_cast<std::uint32_t>(cycle & 0xFFFF) << 16) | (item & 0xFFFF);
}

}  // namespace

std::string_view to_string(SlaveAnswer a) noexcept {
  switch (a) {
    case SlaveAnswer::Unknown: return "unknown";
    case SlaveAnswer::Answered: return "answered";
    case SlaveAnswer::Missing: return "missing";
  }
  return "?";
}

CyclicExchange::CyclicExchange(const ProcessImage& image, CyclicOptions options) noexcept
    : image_(image), options_(options) {
  counters_.expected_wkc = image.expected_wkc();
}

std::span<std::uint8_t> CyclicExchange::outputs(std::size_t slave) noexcept {
  if (slave >= image_.slave_count()) return {};
  const SlaveImage& s = image_.slave(slave);
  return std::span<std::uint8_t>(out_).subspan(s.output_offset, s.output_bytes);
}

std::span<const std::uint8_t> CyclicExchange::inputs(std::size_t slave) const noexcept {
  if (slave >= image_.slave_count()) return {};
  const SlaveImage& s = image_.slave(slave);
  return std::span<const std::uint8_t>(in_).subspan(s.input_offset, s.input_bytes);
}

bool CyclicExchange::queue(Transactions& tx) noexcept {
  if (!image_.ok()) return false;
  ++cycle_;
  ++counters_.cycles;
  CycleSlot& slot = ring_[cycle_ % kRing];
  if (slot.cycle != 0) {
    // Still waiting for results kRing cycles later: the frame is as good as lost.
    slot.lost = true;
    complete(slot);
  }
  slot = CycleSlot{cycle_, 0, 0, 0, false, false};
  bool all = true;
  // The AL status check first: it is one of the image's extra datagrams, planned at the start of
  // the first frame (after DC's FRMW, queued before this) [ProcessImage's header comment].
  if (options_.al_status_check && image_.slave_count() > 0) {
    const std::size_t k = round_robin_++ % image_.slave_count();
    if (tx.queue(this, make_tag(cycle_, kAlItem | static_cast<std::uint32_t>(k)), Command::FPRD,
                 physical_address(image_.slave(k).station, reg::kAlStatus), 2)) {
      ++slot.expected;
      al_queued_[k] = cycle_;
    } else {
      ++counters_.refused;
      all = false;
    }
  }
  const auto datagrams = image_.datagrams();
  for (std::size_t i = 0; i < datagrams.size(); ++i) {
    const CyclicDatagram& d = datagrams[i];
    // LRW/LWR carry the outputs (the input bytes of an LRW go out as they are and come back
    // replaced by the slaves' read FMMUs); an LRD carries nothing [ETG.1000.4 §5.4].
    std::span<const std::uint8_t> data{};
    if (d.command != Command::LRD) data = std::span<const std::uint8_t>(out_).subspan(d.image_offset, d.length);
    if (tx.queue(this, make_tag(cycle_, static_cast<std::uint32_t>(i)), d.command, d.logical_address, d.length, data)) {
      ++slot.expected;
    } else {
      ++counters_.refused;
      slot.lost = true;
      all = false;
    }
  }
  if (slot.expected == 0) complete(slot);
  return all;
}

void CyclicExchange::copy_inputs(const CyclicDatagram& d, std::span<const std::uint8_t> data) noexcept {
  const std::uint32_t lo = d.image_offset;
  const std::uint32_t hi = lo + static_cast<std::uint32_t>(std::min<std::size_t>(data.size(), d.length));
  // A per-slave datagram covers its own slave only: no walk over the others (slaves x datagrams).
  const bool own = d.slave < image_.slave_count();
  const std::size_t first = own ? d.slave : 0;
  const std::size_t last = own ? first + 1 : image_.slave_count();
  for (std::size_t k = first; k < last; ++k) {
    const SlaveImage& s = image_.slave(k);
    if (s.input_bytes == 0) continue;
    const std::uint32_t a = std::max(lo, s.input_offset);
    const std::uint32_t b = std::min(hi, s.input_offset + s.input_bytes);
    if (a >= b) continue;
    std::copy_n(data.begin() + (a - lo), b - a, in_.begin() + a);
    in_cycle_[k] = cycle_;
  }
}

void CyclicExchange::on_result(std::uint32_t tag, const DatagramAnswer& answer) noexcept {
  const std::uint32_t tag_cycle = tag >> 16;
  const std::uint32_t item = tag & 0xFFFF;
  CycleSlot* slot = nullptr;
  for (auto& c : ring_) {
    if (c.cycle != 0 && (c.cycle & 0xFFFF) == tag_cycle) slot = &c;
  }
  if (slot == nullptr) return;  // a cycle already written off
  const bool back = answer.outcome == DatagramOutcome::Answered;
  if ((item & kAlItem) != 0) {
    const std::size_t k = item & ~kAlItem;
    if (k < kMax && al_queued_[k] == slot->cycle) {
      ++counters_.al_checks;
      al_[k].cycle = slot->cycle;
      al_[k].answered = back && answer.wkc == 1 && answer.data.size() >= 2;
      al_[k].raw = al_[k].answered ? static_cast<std::uint16_t>(answer.data[0] | (answer.data[1] << 8)) : 0;
      if (!al_[k].healthy()) ++counters_.al_missing;
    }
  } else if (item < image_.datagrams().size()) {
    const CyclicDatagram& d = image_.datagrams()[item];
    const bool right = back && answer.wkc == d.expected_wkc;
    if (back) slot->wkc = static_cast<std::uint16_t>(slot->wkc + answer.wkc);
    if (!back) slot->lost = true;
    if (back && !right) slot->wkc_wrong = true;
    if (right) copy_inputs(d, answer.data);
    if (d.slave < kMax) (right ? slave_good_cycle_ : slave_bad_cycle_)[d.slave] = slot->cycle;
  }
  if (++slot->results >= slot->expected) complete(*slot);
}

void CyclicExchange::complete(CycleSlot& c) noexcept {
  if (c.cycle == 0) return;
  ++counters_.completed;
  if (c.lost) {
    ++counters_.lost;
  } else if (c.wkc_wrong) {
    ++counters_.wkc_errors;
  } else {
    ++counters_.good;
  }
  if (c.cycle >= last_completed_) {
    last_completed_ = c.cycle;
    last_good_ = !c.lost && !c.wkc_wrong;
    counters_.last_wkc = c.wkc;
  }
  c.cycle = 0;
}

SlaveAnswer CyclicExchange::answered(std::size_t slave) const noexcept {
  if (slave >= image_.slave_count() || last_completed_ == 0) return SlaveAnswer::Unknown;
  if (image_.options().datagrams == CyclicDatagrams::PerSlave) {
    const SlaveImage& s = image_.slave(slave);
    if (s.output_bytes + s.input_bytes > 0) {
      if (slave_bad_cycle_[slave] == last_completed_) return SlaveAnswer::Missing;
      if (slave_good_cycle_[slave] == last_completed_) return SlaveAnswer::Answered;
      return SlaveAnswer::Unknown;
    }
  } else if (last_good_) {
    return SlaveAnswer::Answered;
  }
  // From the slave's last AL status check, if it is recent enough (once per slave_count() cycles).
  const SlaveAlCheck& a = al_[slave];
  if (!options_.al_status_check || a.cycle == 0 || a.cycle + image_.slave_count() < last_completed_) {
    return SlaveAnswer::Unknown;
  }
  return a.healthy() ? SlaveAnswer::Answered : SlaveAnswer::Missing;
}

}  // namespace drivegate::ethercat
