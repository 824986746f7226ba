#pragma once
// The logical process image of a line: where each slave's outputs and inputs sit, the SyncManager
// and FMMU entries that put them there, the cyclic datagrams that move them, the working counter
// they must come back with, and whether the frame fits the wire and the cycle. Pure layout: no
// I/O, no time, no allocation (fixed capacities).
//
// Facts it is built on:
// - SM2 carries the outputs (RxPDOs, master -> slave, buffered, ECAT writes), SM3 the inputs
//   (TxPDOs, buffered, ECAT reads) [ETG.1000.6 SM communication type object 1C00h: 3 outputs, 4 inputs; digest §7.4].
//   Their length is the sum of the assigned PDOs' entry bits, rounded up to bytes per SM
//   [digest §7.4 "SM2 length = sum of the byte sizes of the assigned RxPDOs"].
// - A buffered (3-buffer) SM uses three times its length of ESC memory from its start address
//   [ETG.1000.4 §6 SyncManager, buffered mode]; the room an SM has is therefore a third of the
//   distance to the next SM the SII places above it.
// - An FMMU entry maps a logical range onto physical memory, type 1 read / 2 write
//   [ETG.1000.4 Table 56]. Here FMMU0 maps the outputs (write), FMMU1 the inputs (read), unless
//   the SII FMMU category names other FMMUs for them [ETG.1000.6 §5.4 FMMU category].
// - Working counter of logical commands: a slave that reads in the range adds 1, one that writes
//   adds 1 (LWR) or 2 (LRW) [ETG.1000.4 §5.4, logical commands]; with outputs and inputs a slave adds 3 to an LRW
//   [digest "What a master must do", step 6].
// - A slave whose SII general category sets "enable not LRW" (flags bit 1) needs LRD and LWR
//   instead of LRW [ETG.1000.6 §5.4 General category, Table 21].
//
// Layout: per slave, in line order, its outputs and then its inputs (interleaved). One LRW covers
// the whole image; a slave's own bytes are one contiguous range, so per-slave datagrams are
// possible too (CyclicDatagrams::PerSlave). When any slave needs LRD+LWR, the whole-image mode
// sends one LWR and one LRD over the whole image (twice the bytes), the per-slave mode an LWR+LRD
// pair for those slaves only.
//
// Frames: the cycle's datagrams may span up to kMaxFrames Ethernet frames (each at most 1514
// bytes, so at most 124 datagrams), as SOEM and the IgH master split a large image over several frames.
// They are planned the way Transactions::queue() packs them: in queue order, each datagram into
// the newest frame while it has room for it, else into a new frame. The extra datagrams (DC's
// FRMW, then the AL status check) are queued first and so sit at the start of the first frame.
// A whole-image LRW (or LWR/LRD) that does not fit in the room left in a frame is cut at slave
// boundaries into several datagrams (one per frame), each with the working counter of its slaves.
// kMaxFrames is 4: four full frames take 4 x 1538 bytes x 80 ns = 492 us on the wire, half of a
// 1 ms cycle (fits() refuses more at 1 kHz anyway); 64 generic drives with one LRW of 32 bytes
// each need 2 (66 datagrams, 2850 bytes).
//
// Frame time on the wire at 100 Mbit/s: 8 bytes preamble and SFD + the frame (at least 60 bytes)
// + 4 bytes FCS + 12 bytes inter-frame gap, 80 ns per byte [IEEE 802.3 §4.4.2, §3.1.1].
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "adapters/ethercat/wire/frame.hpp"
#include "adapters/ethercat/wire/registers.hpp"
#include "adapters/ethercat/wire/sii.hpp"
#include "core/clock.hpp"
#include "core/fixed_string.hpp"

namespace drivegate::ethercat {

// A process data SyncManager as the SII describes it (or our default).
struct ProcessSm {
  std::uint16_t start = 0;       // ESC address of the first buffer
  std::uint8_t control = 0;      // control byte (SM2 typically 64h, SM3 20h)
  std::uint16_t capacity = 0;    // bytes the SM may carry (3 buffers fit below the next SM); 0 = not known
};

// What the layout needs to know about one slave.
struct ImageSlave {
  std::uint16_t station = 0;
  std::uint16_t output_bytes = 0;  // SM2 length
  std::uint16_t input_bytes = 0;   // SM3 length
  ProcessSm sm2{reg::kProcessRam, sm_control::kOutputs, 0};
  ProcessSm sm3{reg::kProcessRam, sm_control::kInputs, 0};
  std::uint8_t fmmu_outputs = 0;   // FMMU index for the outputs (write)
  std::uint8_t fmmu_inputs = 1;    // FMMU index for the inputs (read)
  bool lrd_lwr = false;            // the slave does not take LRW
};

// Bytes of `bits` rounded up (an SM's length is whole bytes).
constexpr std::uint16_t bytes_of_bits(std::uint32_t bits) noexcept {
  return static_cast<std::uint16_t>((bits + 7U) / 8U);
}

// The slave's SM2/SM3 start, control byte and room from its SII SyncM category, its FMMU choice
// from the FMMU category and "not LRW" from the general category; defaults where the SII says
// nothing: SM2 right after the mailbox (or at 1000h), SM3 after SM2's three buffers, control 64h
// and 20h, FMMU0/FMMU1, capacity unknown.
ImageSlave image_slave_from_sii(const SiiInfo& sii, std::uint16_t station, std::uint32_t output_bits,
                                std::uint32_t input_bits) noexcept;

enum class CyclicDatagrams : std::uint8_t {
  WholeImage,  // one LRW over the image (or LWR + LRD when a slave needs them)
  PerSlave,    // one LRW per slave over its own range (LWR + LRD for those that need them)
};

struct ImageOptions {
  std::uint32_t logical_base = 0;  // logical address of the image's first byte
  CyclicDatagrams datagrams = CyclicDatagrams::WholeImage;
  // Other datagrams the cycle queues before the image's, so at the start of its first frame (DC's
  // FRMW: 12 + 8 bytes, then the AL status check of CyclicExchange: 12 + 2 bytes).
  std::size_t extra_datagrams = 1;
  std::size_t extra_data_bytes = 2;
};

enum class ImageError : std::uint8_t {
  None,
  TooManySlaves,    // more than ProcessImage::kMaxSlaves
  BadSmAddress,     // an SM with data below the process RAM (1000h) or beyond 64 KiB
  OutputsBeyondSm,  // a slave's outputs larger than its SM2's room
  InputsBeyondSm,   // a slave's inputs larger than its SM3's room
  SmOverlap,        // SM2's and SM3's buffers overlap
  SameFmmu,         // outputs and inputs on one FMMU, or an FMMU index beyond 15
  FrameTooLarge,    // the cyclic datagrams do not fit in ProcessImage::kMaxFrames Ethernet frames
};
std::string_view to_string(ImageError e) noexcept;

// A slave's place in the image and the entries that put it there.
struct SlaveImage {
  std::uint16_t station = 0;
  std::uint32_t output_offset = 0;  // in the image (logical address = base + offset)
  std::uint16_t output_bytes = 0;
  std::uint32_t input_offset = 0;
  std::uint16_t input_bytes = 0;
  bool lrd_lwr = false;
  SmEntry sm2{};                    // written to 0810h
  SmEntry sm3{};                    // written to 0818h
  std::uint8_t fmmu_outputs_index = 0;
  FmmuEntry fmmu_outputs{};         // inactive (all zero) without outputs
  std::uint8_t fmmu_inputs_index = 1;
  FmmuEntry fmmu_inputs{};          // inactive without inputs
  std::uint16_t expected_wkc = 0;   // what this slave adds to its datagrams (LRW 2 + 1, LWR/LRD 1)
};

// One datagram of the cycle.
struct CyclicDatagram {
  Command command = Command::LRW;
  std::uint32_t logical_address = 0;
  std::uint32_t image_offset = 0;  // of its first byte in the image
  std::uint16_t length = 0;
  std::uint16_t expected_wkc = 0;
  std::uint16_t slave = 0xFFFF;    // PerSlave: the slave (index into slaves()); WholeImage: FFFFh
  std::uint8_t frame = 0;          // the frame of the cycle it goes in (0: the first)
};

// One Ethernet frame of the cycle.
struct CyclicFrame {
  std::size_t datagrams = 0;  // all of them: the extra ones (first frame) and the image's
  std::size_t bytes = 0;      // Ethernet + EtherCAT headers + datagrams, padded to 60, without FCS
};

class ProcessImage {
 public:
  static constexpr std::size_t kMaxSlaves = 64;
  static constexpr std::size_t kMaxDatagrams = 2 * kMaxSlaves;
  // Frames per cycle (see the header comment for why 4).
  static constexpr std::size_t kMaxFrames = 4;
  // Image bytes: as much as kMaxFrames frames of one datagram each carry.
  static constexpr std::size_t kMaxBytes = kMaxFrames * kMaxDatagramData;
  // As Transactions: as many as a frame can hold (wire/frame.hpp).
  static constexpr std::size_t kMaxDatagramsPerFrame = ethercat::kMaxDatagramsPerFrame;

  // Lays out `slaves` (line order). Returns ok(); on failure error() and text() say why and the
  // layout is empty.
  bool build(std::span<const ImageSlave> slaves, const ImageOptions& options = {}) noexcept;

  [[nodiscard]] bool ok() const noexcept { return error_ == ImageError::None && built_; }
  [[nodiscard]] ImageError error() const noexcept { return error_; }
  [[nodiscard]] std::string_view text() const noexcept { return text_.view(); }

  [[nodiscard]] const ImageOptions& options() const noexcept { return options_; }
  [[nodiscard]] std::size_t slave_count() const noexcept { return count_; }
  [[nodiscard]] const SlaveImage& slave(std::size_t k) const noexcept { return slaves_[k]; }
  [[nodiscard]] std::uint32_t size() const noexcept { return size_; }  // image bytes
  [[nodiscard]] std::span<const CyclicDatagram> datagrams() const noexcept { return {datagrams_.data(), datagram_count_}; }
  [[nodiscard]] std::uint16_t expected_wkc() const noexcept { return expected_wkc_; }

  // The cycle's frames, in the order they are sent.
  [[nodiscard]] std::span<const CyclicFrame> frames() const noexcept { return {frames_.data(), frame_count_}; }
  [[nodiscard]] std::size_t frame_count() const noexcept { return frame_count_; }
  // All the cycle's frames: Ethernet + EtherCAT headers + the datagrams (+ the extra ones), each
  // padded to 60 bytes, without FCS.
  [[nodiscard]] std::size_t frame_bytes() const noexcept { return frame_bytes_; }
  // On the wire: + preamble/SFD 8, FCS 4, inter-frame gap 12 per frame.
  [[nodiscard]] std::size_t wire_bytes() const noexcept { return frame_bytes_ + 24 * frame_count_; }
  // Time the frames occupy the wire at 100 Mbit/s (sent back to back).
  [[nodiscard]] core::Duration wire_time() const noexcept { return core::Duration(80 * static_cast<std::int64_t>(wire_bytes())); }
  // Time from sending the first frame to having the last back: the wire time of all of them plus
  // every slave's forwarding delay out and back (`per_slave`, about 1 µs for an ESC with two
  // 100BASE-TX ports).
  [[nodiscard]] core::Duration round_trip(core::Duration per_slave = std::chrono::microseconds(1)) const noexcept {
    return wire_time() + per_slave * static_cast<std::int64_t>(count_);
  }
  // The frames are back within `share` of the cycle (default: half, leaving the rest for the
  // mailbox traffic and the application).
  [[nodiscard]] bool fits(core::Duration cycle, double share = 0.5,
                          core::Duration per_slave = std::chrono::microseconds(1)) const noexcept {
    return ok() && static_cast<double>(round_trip(per_slave).count()) <= share * static_cast<double>(cycle.count());
  }

 private:
  bool fail(ImageError e, const char* fmt, ...) noexcept __attribute__((format(printf, 3, 4)));
  bool place_sms(std::size_t k, const ImageSlave& in) noexcept;
  // Plans a datagram of `length` data bytes as Transactions::queue() packs it; false when it would
  // need a frame beyond kMaxFrames.
  bool add_datagram(Command c, std::uint32_t offset, std::uint32_t length, std::uint16_t wkc, std::uint16_t slave) noexcept;
  // Data bytes the newest frame still takes in one more datagram (0: none, it is full).
  [[nodiscard]] std::size_t room() const noexcept;
  void open_frame() noexcept;
  // WholeImage: `command` over the image, cut at slave boundaries where a frame's room ends.
  bool add_whole(Command command) noexcept;

  ImageOptions options_{};
  std::array<SlaveImage, kMaxSlaves> slaves_{};
  std::size_t count_ = 0;
  std::array<CyclicDatagram, kMaxDatagrams> datagrams_{};
  std::size_t datagram_count_ = 0;
  std::uint32_t size_ = 0;
  std::uint16_t expected_wkc_ = 0;
  std::array<CyclicFrame, kMaxFrames> frames_{};
  std::size_t frame_count_ = 0;
  std::size_t frame_bytes_ = 0;
  // Frames planned so far (may pass kMaxFrames while planning: the refusal says how many), and
  // the newest one's datagrams and bytes.
  std::size_t planned_frames_ = 0;
  std::size_t open_datagrams_ = 0;
  std::size_t open_bytes_ = 0;
  bool built_ = false;
  ImageError error_ = ImageError::None;
  core::FixedString<200> text_{};
};

}  // namespace drivegate::ethercat
