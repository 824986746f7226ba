#include "adapters/ethercat/master/process_image.hpp"

#include <algorithm>
#include <cstdarg>

namespace drivegate::ethercat {

namespace {

// A buffered SM occupies three buffers of its length [ETG.1000.4 §6 SyncManager, buffered mode].
constexpr std::uint32_t kBuffers = 3;
constexpr std::uint32_t kEscMemoryEnd = 0x10000;
constexpr std::uint8_t kMaxFmmuIndex = 15;  // 16 FMMU entries at 0600h..06FFh [ETG.1000.4 Table 56]
constexpr std::uint8_t kGeneralFlagNotLrw = 0x02;  // "enable not LRW" [ETG.1000.6 Table 21]

// Room of an SM starting at `start`: a third of the distance to the next SM start above it in the
// SII (0 = nothing above it: not known).
std::uint16_t room_below_next_sm(const SiiInfo& sii, std::uint16_t start) noexcept {
  std::uint32_t next = 0;
  for (std::size_t i = 0; i < sii.sync_manager_count; ++i) {
    const std::uint16_t s = sii.sync_managers[i].physical_start;
    if (s > start && (next == 0 || s < next)) next = s;
  }
  if (next == 0) return 0;
  return static_cast<std::uint16_t>((next - start) / kBuffers);
}

bool sii_sm(const SiiInfo& sii, std::size_t n, std::uint8_t type, SiiSyncManager& out) noexcept {
  if (n >= sii.sync_manager_count) return false;
  const SiiSyncManager& s = sii.sync_managers[n];
  if (s.type != type || s.physical_start < reg::kProcessRam) return false;
  out = s;
  return true;
}

}  // namespace

std::string_view to_string(ImageError e) noexcept {
  switch (e) {
    case ImageError::None: return "none";
    case ImageError::TooManySlaves: return "too many slaves";
    case ImageError::BadSmAddress: return "SM address outside the process RAM";
    case ImageError::OutputsBeyondSm: return "outputs larger than SM2";
    case ImageError::InputsBeyondSm: return "inputs larger than SM3";
    case ImageError::SmOverlap: return "SM2 and SM3 overlap";
    case ImageError::SameFmmu: return "invalid FMMU choice";
    case ImageError::FrameTooLarge: return "cyclic datagrams need more Ethernet frames than a cycle sends";
  }
  return "?";
}

ImageSlave image_slave_from_sii(const SiiInfo& sii, std::uint16_t station, std::uint32_t output_bits,
                                std::uint32_t input_bits) noexcept {
  ImageSlave s;
  s.station = station;
  s.output_bytes = bytes_of_bits(output_bits);
  s.input_bytes = bytes_of_bits(input_bits);
  // Defaults (our choice where the SII has no SyncM category): SM2 after the mailbox buffers, SM3
  // after SM2's three buffers.
  std::uint32_t after_mailbox = reg::kProcessRam;
  const SiiMailbox& mb = sii.header.standard_mailbox;
  if (mb.present()) {
    after_mailbox = std::max<std::uint32_t>({after_mailbox, std::uint32_t{mb.rx_offset} + mb.rx_size,
                                             std::uint32_t{mb.tx_offset} + mb.tx_size});
  }
  SiiSyncManager sm{};
  if (sii_sm(sii, 2, sii_sm_type::kOutputs, sm)) {
    s.sm2 = ProcessSm{sm.physical_start, sm.control != 0 ? sm.control : sm_control::kOutputs,
                      room_below_next_sm(sii, sm.physical_start)};
  } else {
    s.sm2 = ProcessSm{static_cast<std::uint16_t>(std::min<std::uint32_t>(after_mailbox, 0xFFFF)), sm_control::kOutputs, 0};
  }
  if (sii_sm(sii, 3, sii_sm_type::kInputs, sm)) {
    s.sm3 = ProcessSm{sm.physical_start, sm.control != 0 ? sm.control : sm_control::kInputs,
                      room_below_next_sm(sii, sm.physical_start)};
  } else {
    const std::uint32_t at = std::uint32_t{s.sm2.start} + kBuffers * s.output_bytes;
    s.sm3 = ProcessSm{static_cast<std::uint16_t>(std::min<std::uint32_t>(at, 0xFFFF)), sm_control::kInputs, 0};
  }
  // FMMUs by their SII usage [ETG.1000.6 §5.4 FMMU category]: the first one for outputs, the first
  // for inputs; 0 and 1 otherwise (never both on one FMMU).
  int out_fmmu = -1;
  int in_fmmu = -1;
  for (std::size_t i = 0; i < sii.fmmu_count; ++i) {
    if (out_fmmu < 0 && sii.fmmus[i] == sii_fmmu_usage::kOutputs) out_fmmu = static_cast<int>(i);
    if (in_fmmu < 0 && sii.fmmus[i] == sii_fmmu_usage::kInputs) in_fmmu = static_cast<int>(i);
  }
  if (out_fmmu < 0) out_fmmu = in_fmmu == 0 ? 1 : 0;
  if (in_fmmu < 0) in_fmmu = out_fmmu == 1 ? 0 : 1;
  if (in_fmmu == out_fmmu) in_fmmu = out_fmmu + 1;
  s.fmmu_outputs = static_cast<std::uint8_t>(out_fmmu);
  s.fmmu_inputs = static_cast<std::uint8_t>(in_fmmu);
  s.lrd_lwr = sii.has_general && (sii.general.flags & kGeneralFlagNotLrw) != 0;
  return s;
}

bool ProcessImage::fail(ImageError e, const char* fmt, ...) noexcept {
  error_ = e;
  va_list args;
  va_start(args, fmt);
  text_.vformat(fmt, args);
  va_end(args);
  count_ = 0;
  datagram_count_ = 0;
  size_ = 0;
  expected_wkc_ = 0;
  frame_count_ = 0;
  frame_bytes_ = 0;
  return false;
}

bool ProcessImage::place_sms(std::size_t k, const ImageSlave& in) noexcept {
  const unsigned n = static_cast<unsigned>(k + 1);
  auto check = [&](const ProcessSm& sm, std::uint16_t bytes, unsigned index, ImageError beyond, const char* what) {
    if (bytes == 0) return true;
    const std::uint32_t end = std::uint32_t{sm.start} + kBuffers * bytes;
    if (sm.start < reg::kProcessRam || end > kEscMemoryEnd) {
      return fail(ImageError::BadSmAddress,
                  "slave %u (0x%04X): SM%u at %04Xh with %u %s bytes (3 buffers) is outside the process RAM 1000h-FFFFh",
                  n, in.station, index, sm.start, bytes, what);
    }
    if (sm.capacity != 0 && bytes > sm.capacity) {
      return fail(beyond, "slave %u (0x%04X): %u %s bytes do not fit SM%u at %04Xh (room for %u bytes, 3 buffers, before the next SM)",
                  n, in.station, bytes, what, index, sm.start, sm.capacity);
    }
    return true;
  };
  if (!check(in.sm2, in.output_bytes, 2, ImageError::OutputsBeyondSm, "output")) return false;
  if (!check(in.sm3, in.input_bytes, 3, ImageError::InputsBeyondSm, "input")) return false;
  if (in.output_bytes > 0 && in.input_bytes > 0) {
    const std::uint32_t a0 = in.sm2.start;
    const std::uint32_t a1 = a0 + kBuffers * in.output_bytes;
    const std::uint32_t b0 = in.sm3.start;
    const std::uint32_t b1 = b0 + kBuffers * in.input_bytes;
    if (a0 < b1 && b0 < a1) {
      return fail(ImageError::SmOverlap, "slave %u (0x%04X): SM2 %04Xh-%04Xh and SM3 %04Xh-%04Xh overlap (3 buffers each)", n,
                  in.station, a0, a1 - 1, b0, b1 - 1);
    }
    if (in.fmmu_outputs == in.fmmu_inputs) {
      return fail(ImageError::SameFmmu, "slave %u (0x%04X): outputs and inputs both on FMMU%u", n, in.station, in.fmmu_outputs);
    }
  }
  if ((in.output_bytes > 0 && in.fmmu_outputs > kMaxFmmuIndex) || (in.input_bytes > 0 && in.fmmu_inputs > kMaxFmmuIndex)) {
    return fail(ImageError::SameFmmu, "slave %u (0x%04X): FMMU index beyond 15", n, in.station);
  }
  SlaveImage& s = slaves_[k];
  s.sm2 = SmEntry{in.sm2.start, in.output_bytes, in.sm2.control, 0,
                  in.output_bytes > 0 ? sm_activate::kEnable : std::uint8_t{0}, 0};
  s.sm3 = SmEntry{in.sm3.start, in.input_bytes, in.sm3.control, 0,
                  in.input_bytes > 0 ? sm_activate::kEnable : std::uint8_t{0}, 0};
  s.fmmu_outputs_index = in.fmmu_outputs;
  s.fmmu_inputs_index = in.fmmu_inputs;
  // An unused FMMU is written all zero (FmmuEntry{} has stop bit 7): cleared, inactive.
  constexpr FmmuEntry kCleared{0, 0, 0, 0, 0, 0, 0, false};
  s.fmmu_outputs = kCleared;
  s.fmmu_inputs = kCleared;
  if (in.output_bytes > 0) {
    s.fmmu_outputs = FmmuEntry{options_.logical_base + s.output_offset, in.output_bytes, 0, 7, in.sm2.start, 0,
                               fmmu_type::kWrite, true};
  }
  if (in.input_bytes > 0) {
    s.fmmu_inputs = FmmuEntry{options_.logical_base + s.input_offset, in.input_bytes, 0, 7, in.sm3.start, 0,
                              fmmu_type::kRead, true};
  }
  return true;
}

std::size_t ProcessImage::room() const noexcept {
  // As Transactions::queue(): a frame takes a datagram while it has fewer than 124 and room for
  // its 12 bytes of header and WKC and its data within 1514 bytes [ETG.1000.4 §5.3-§5.4].
  if (planned_frames_ == 0 || open_datagrams_ >= kMaxDatagramsPerFrame) return 0;
  const std::size_t used = open_bytes_ + kDatagramOverhead;
  return used < kMaxFrameSize ? kMaxFrameSize - used : 0;
}

void ProcessImage::open_frame() noexcept {
  ++planned_frames_;
  open_datagrams_ = 0;
  open_bytes_ = kEthernetHeaderSize + kEcatHeaderSize;
}

bool ProcessImage::add_datagram(Command c, std::uint32_t offset, std::uint32_t length, std::uint16_t wkc,
                                std::uint16_t slave) noexcept {
  if (length > room() && open_datagrams_ > 0) open_frame();
  if (length > room()) {
    return fail(ImageError::FrameTooLarge, "%u bytes of process data in one datagram: one Ethernet frame carries %zu", length,
                kMaxDatagramData);
  }
  if (datagram_count_ >= datagrams_.size()) {  // cannot happen: at most 2 per slave
    return fail(ImageError::FrameTooLarge, "more than %zu cyclic datagrams", datagrams_.size());
  }
  datagrams_[datagram_count_++] = CyclicDatagram{c, options_.logical_base + offset, offset, static_cast<std::uint16_t>(length), wkc,
                                                 slave, static_cast<std::uint8_t>(std::min<std::size_t>(planned_frames_ - 1, 0xFF))};
  ++open_datagrams_;
  open_bytes_ += kDatagramOverhead + length;
  if (planned_frames_ <= kMaxFrames) {
    frames_[planned_frames_ - 1] = CyclicFrame{open_datagrams_, std::max(open_bytes_, kMinFrameSize)};
  }
  return true;
}

bool ProcessImage::add_whole(Command command) noexcept {
  // Working counter of a slave in a logical datagram [ETG.1000.4 §5.4]: read +1; write +1 (LWR)
  // or +2 (LRW).
  const auto wkc_of = [command](const SlaveImage& s) {
    const int reads = s.input_bytes > 0 ? 1 : 0;
    const int writes = s.output_bytes > 0 ? 1 : 0;
    switch (command) {
      case Command::LWR: return writes;
      case Command::LRD: return reads;
      default: return reads + 2 * writes;
    }
  };
  std::size_t k = 0;
  while (k < count_) {
    // One datagram: the slaves from k on while they fit in the newest frame's room; a slave that
    // does not fit starts the next datagram (in a new frame, as Transactions::queue() would put it).
    const std::uint32_t lo = slaves_[k].output_offset;
    std::uint32_t hi = lo;
    int wkc = 0;
    while (k < count_) {
      const SlaveImage& s = slaves_[k];
      const std::uint32_t bytes = std::uint32_t{s.output_bytes} + s.input_bytes;
      if (hi - lo + bytes > room()) {
        if (hi > lo) break;
        if (open_datagrams_ > 0) {
          open_frame();
          continue;
        }
        return fail(ImageError::FrameTooLarge, "slave %zu (0x%04X): %u bytes of process data, one Ethernet frame carries %zu",
                    k + 1, s.station, bytes, kMaxDatagramData);
      }
      hi += bytes;
      wkc += wkc_of(s);
      ++k;
    }
    if (hi > lo && !add_datagram(command, lo, hi - lo, static_cast<std::uint16_t>(wkc), 0xFFFF)) return false;
  }
  return true;
}

bool ProcessImage::build(std::span<const ImageSlave> slaves, const ImageOptions& options) noexcept {
  options_ = options;
  built_ = false;
  error_ = ImageError::None;
  text_.clear();
  count_ = 0;
  datagram_count_ = 0;
  size_ = 0;
  expected_wkc_ = 0;
  frame_count_ = 0;
  frame_bytes_ = 0;
  planned_frames_ = 0;
  if (slaves.size() > kMaxSlaves) {
    return fail(ImageError::TooManySlaves, "%zu slaves with process data: at most %zu", slaves.size(), kMaxSlaves);
  }
  std::uint32_t offset = 0;
  bool any_lrd_lwr = false;
  std::uint16_t readers_wkc = 0;
  std::uint16_t writers_wkc = 0;
  std::uint16_t lrw_wkc = 0;
  for (std::size_t k = 0; k < slaves.size(); ++k) {
    const ImageSlave& in = slaves[k];
    SlaveImage& s = slaves_[k];
    s = SlaveImage{};
    s.station = in.station;
    s.lrd_lwr = in.lrd_lwr;
    s.output_offset = offset;
    s.output_bytes = in.output_bytes;
    offset += in.output_bytes;
    s.input_offset = offset;
    s.input_bytes = in.input_bytes;
    offset += in.input_bytes;
    if (!place_sms(k, in)) return false;
    // Working counter per slave [ETG.1000.4 §5.4, logical commands]: read +1; write +1 (LWR) or +2 (LRW).
    const std::uint16_t reads = in.input_bytes > 0 ? 1 : 0;
    const std::uint16_t writes = in.output_bytes > 0 ? 1 : 0;
    s.expected_wkc = static_cast<std::uint16_t>(reads + (in.lrd_lwr ? writes : 2 * writes));
    readers_wkc = static_cast<std::uint16_t>(readers_wkc + reads);
    writers_wkc = static_cast<std::uint16_t>(writers_wkc + writes);
    lrw_wkc = static_cast<std::uint16_t>(lrw_wkc + reads + 2 * writes);
    any_lrd_lwr = any_lrd_lwr || in.lrd_lwr;
  }
  count_ = slaves.size();
  size_ = offset;

  // The first frame starts with the extra datagrams (queued first, DC's FRMW first).
  open_frame();
  open_datagrams_ = options_.extra_datagrams;
  open_bytes_ += kDatagramOverhead * options_.extra_datagrams + options_.extra_data_bytes;
  frames_[0] = CyclicFrame{open_datagrams_, std::max(open_bytes_, kMinFrameSize)};
  if (options_.datagrams == CyclicDatagrams::WholeImage) {
    if (size_ > 0 && !any_lrd_lwr) {
      if (!add_whole(Command::LRW)) return false;
    } else if (size_ > 0) {
      if (!add_whole(Command::LWR) || !add_whole(Command::LRD)) return false;
    }
  } else {
    for (std::size_t k = 0; k < count_; ++k) {
      const SlaveImage& s = slaves_[k];
      const auto slave = static_cast<std::uint16_t>(k);
      if (s.output_bytes + s.input_bytes == 0) continue;
      if (!s.lrd_lwr) {
        if (!add_datagram(Command::LRW, s.output_offset, std::uint32_t{s.output_bytes} + s.input_bytes, s.expected_wkc, slave))
          return false;
        continue;
      }
      if (s.output_bytes > 0 && !add_datagram(Command::LWR, s.output_offset, s.output_bytes, 1, slave)) return false;
      if (s.input_bytes > 0 && !add_datagram(Command::LRD, s.input_offset, s.input_bytes, 1, slave)) return false;
    }
  }
  expected_wkc_ = 0;
  for (std::size_t i = 0; i < datagram_count_; ++i) {
    expected_wkc_ = static_cast<std::uint16_t>(expected_wkc_ + datagrams_[i].expected_wkc);
  }
  if (planned_frames_ > kMaxFrames) {
    return fail(ImageError::FrameTooLarge,
                "process image of %u bytes: its %zu cyclic datagrams (and %zu more) need %zu Ethernet frames, a cycle "
                "sends at most %zu (of 1514 bytes each)",
                offset, datagram_count_, options_.extra_datagrams, planned_frames_, kMaxFrames);
  }
  frame_count_ = planned_frames_;
  frame_bytes_ = 0;
  for (std::size_t i = 0; i < frame_count_; ++i) frame_bytes_ += frames_[i].bytes;
  built_ = true;
  return true;
}

}  // namespace drivegate::ethercat
