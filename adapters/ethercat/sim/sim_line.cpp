#include "adapters/ethercat/sim/sim_line.hpp"

#include <algorithm>
#include <cstdint>

namespace drivegate::ethercat::sim {

SimLine::SimLine(MemoryLink& link, SimLineConfig config) : link_(link), cfg_(config) {
  slaves_.reserve(64);
  link_.set_sink(this);
}

SimLine::~SimLine() { link_.set_sink(nullptr); }

std::size_t SimLine::add(EscSlave& slave) { return add(slave, cfg_.hop_delay_ns); }

std::size_t SimLine::add(EscSlave& slave, std::uint32_t hop_delay_ns) {
  slaves_.push_back(Entry{&slave, true, hop_delay_ns});
  update_links();
  return slaves_.size() - 1;
}

std::size_t SimLine::reachable() const noexcept {
  std::size_t n = 0;
  while (n < slaves_.size() && slaves_[n].powered) {
    ++n;
    if (n - 1 == break_after_) break;
  }
  return n;
}

void SimLine::update_links() noexcept {
  // Port 1 has a link when the next slave is powered and the cable to it is whole.
  for (std::size_t k = 0; k < slaves_.size(); ++k) {
    if (!slaves_[k].powered) continue;
    const bool next_up = k + 1 < slaves_.size() && slaves_[k + 1].powered && k != break_after_;
    slaves_[k].esc->set_port1_link(next_up);
  }
}

void SimLine::power_off(std::size_t k) noexcept {
  if (k >= slaves_.size()) return;
  slaves_[k].powered = false;
  update_links();
}

void SimLine::power_on(std::size_t k) noexcept {
  if (k >= slaves_.size() || slaves_[k].powered) return;
  slaves_[k].powered = true;
  slaves_[k].esc->power_on();  // a real slave boots into INIT with station address 0
  update_links();
}

void SimLine::break_after(std::size_t k) noexcept {
  break_after_ = k;
  update_links();
}

void SimLine::repair_cable() noexcept {
  break_after_ = SIZE_MAX;
  update_links();
}

void SimLine::run_pdi() noexcept {
  for (Entry& e : slaves_) {
    if (e.powered) e.esc->pdi_cycle(now_);
  }
}

void SimLine::advance(std::uint64_t now_ns) noexcept {
  now_ = now_ns;
  run_pdi();
}

void SimLine::on_frame(FrameView frame) noexcept {
  ++counters_.frames;
  if (drop_ > 0) {
    --drop_;
    ++counters_.dropped;
    run_pdi();
    return;
  }
  const std::size_t n = reachable();
  if (corrupt_) {
    corrupt_ = false;
    ++counters_.corrupted;
    if (n > 0) slaves_[0].esc->count_rx_error();
    run_pdi();
    return;
  }
  if (frame.size() > buf_.size()) {
    ++counters_.malformed;
    return;
  }
  std::copy(frame.begin(), frame.end(), buf_.begin());
  const std::span<std::uint8_t> bytes(buf_.data(), frame.size());
  std::size_t count = 0;
  {
    FrameParser parser{std::span<const std::uint8_t>(bytes)};
    Datagram d;
    while (count < datagrams_.size() && parser.next(d)) datagrams_[count++] = d;
    if (parser.error() != FrameError::None) {
      ++counters_.malformed;
      run_pdi();
      return;
    }
  }
  if (n == 0) {
    ++counters_.unreachable;
    run_pdi();
    return;
  }
  std::uint64_t s_last = 0;
  for (std::size_t k = 0; k < n; ++k) s_last += slaves_[k].hop_ns;
  const std::size_t last = n - 1;
  std::uint64_t s_k = 0;
  for (std::size_t k = 0; k < n; ++k) {
    EscSlave& esc = *slaves_[k].esc;
    s_k += slaves_[k].hop_ns;
    const std::uint64_t port0 = now_ + s_k;
    const std::uint64_t port1 = now_ + s_last + (s_last - s_k);
    esc.begin_frame(port0, port1, k < last);
    for (std::size_t i = 0; i < count; ++i) {
      const Datagram& g = datagrams_[i];
      esc.process(g.header, bytes.subspan(g.header_offset, kDatagramHeaderSize), bytes.subspan(g.data_offset, g.header.length),
                  bytes.subspan(g.wkc_offset, kWkcSize));
    }
  }
  // The first slave marks the returning frame's source address as locally administered (bit 1 of
  // the first source byte) [ETG.1000.4 §5.3: the ESC on port 0 changes the source MAC].
  bytes[kEthernetHeaderSize - 8] = static_cast<std::uint8_t>(bytes[kEthernetHeaderSize - 8] | 0x02);
  run_pdi();
  if (link_.deliver(std::span<const std::uint8_t>(bytes))) ++counters_.returned;
}

}  // namespace drivegate::ethercat::sim
