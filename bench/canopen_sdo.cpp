// SDO segmented throughput: an SdoClient (master/sdo_client.hpp) and an SdoServer
// (sim/sdo_server.hpp) backed by one 64-byte buffer object, on the bit-rate-emulating in-process
// bus (transport/inproc_bus.hpp), uploading or downloading the object back to back on virtual time.
// What share of what the wire allows for this protocol does the engine pair achieve, and what does
// polling the engines once per 1 ms cycle, as drivegated does, cost on top?
//
// Every figure is virtual time, so it is the same on every run and on any machine: no repetition
// is needed. The transfers are checked byte for byte and heap allocations in the loop counted
// (expected 0). Figures only; nothing is asserted.
#include <algorithm>
#include <array>
#include <charconv>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <string_view>
#include <vector>

#include "adapters/canopen/master/sdo_client.hpp"
#include "adapters/canopen/sim/sdo_server.hpp"
#include "adapters/canopen/transport/inproc_bus.hpp"
#include "adapters/canopen/wire/bit_timing.hpp"
#include "tests/support/alloc_counter.hpp"

namespace drivegate::bench {
namespace {

using namespace std::chrono_literals;
using canopen::CanFrame;
using canopen::SdoClient;
using canopen::SdoRequestId;
using canopen::SdoStatus;

constexpr std::size_t kObjectSize = SdoClient::kMaxData;  // 64: the largest object one request carries
constexpr canopen::ObjectId kObject{0x2000, 0};
constexpr std::uint32_t kRequestCob = 0x601;  // SDO channel 1 of node 1 [CiA 301 pre-defined set]
constexpr std::uint32_t kResponseCob = 0x581;

// The ideal for this protocol: an initiate request and response, then a request and a response per
// 7-byte segment; every SDO frame has DLC 8 (wire/sdo_codec.hpp).
constexpr std::uint32_t kSegments = (kObjectSize + 6) / 7;
constexpr std::uint32_t kFramesPerObject = 2 * (1 + kSegments);
constexpr std::uint32_t kBitsPerObject = kFramesPerObject * canopen::frame_bits(8);

constexpr std::uint8_t pattern(std::size_t i) noexcept { return static_cast<std::uint8_t>(i * 37 + 11); }

// The object dictionary of the simulated server: one 64-byte object that uploads a known pattern
// and checks every download against it.
class BufferObject final : public canopen::sim::SdoBackend {
 public:
  BufferObject() {
    for (std::size_t i = 0; i < bytes_.size(); ++i) bytes_[i] = pattern(i);
  }
  canopen::sim::SdoReadResult sdo_read(canopen::ObjectId object, std::span<std::uint8_t> out) noexcept override {
    if (object != kObject) return {0x06020000, 0};
    if (out.size() < bytes_.size()) return {0, bytes_.size()};
    std::copy(bytes_.begin(), bytes_.end(), out.begin());
    return {0, bytes_.size()};
  }
  std::uint32_t sdo_write(canopen::ObjectId object, std::span<const std::uint8_t> data) noexcept override {
    if (object != kObject) return 0x06020000;
    if (!std::equal(data.begin(), data.end(), bytes_.begin(), bytes_.end())) ++corrupt_;
    return 0;
  }
  [[nodiscard]] std::uint64_t corrupt() const noexcept { return corrupt_; }

 private:
  std::array<std::uint8_t, kObjectSize> bytes_{};
  std::uint64_t corrupt_ = 0;
};

// When the frames handed to the in-process bus finish, as it schedules them: a frame starts once
// it is queued and the medium is free, and reaches the others frame_time() later. All SDO frames
// are equally long, so the order arbitration picks does not change the end times.
class WireSchedule {
 public:
  explicit WireSchedule(std::uint32_t bitrate) : bitrate_(bitrate) { ends_.reserve(64); }
  void sent(core::TimePoint at) {
    free_ = std::max(free_, at) + canopen::frame_time(8, bitrate_);
    ends_.push_back(free_);
  }
  // The first delivery after `now` (TimePoint::max() when nothing is on its way).
  core::TimePoint next_after(core::TimePoint now) {
    std::erase_if(ends_, [now](core::TimePoint t) { return t <= now; });
    return ends_.empty() ? core::TimePoint::max() : ends_.front();
  }

 private:
  std::uint32_t bitrate_;
  core::TimePoint free_{};
  std::vector<core::TimePoint> ends_;
};

// When each side's engine runs: whenever a frame arrives, or at each tick of the cycle.
struct Polling {
  const char* name;
  bool client_on_arrival;
  bool server_on_arrival;
};
constexpr core::Duration kCycle = 1ms;
constexpr std::array kPollings{
    Polling{"on arrival", true, true},
    Polling{"1 ms cycle", false, false},
    Polling{"1 ms cycle, drive on arrival", false, true},
};

enum class Direction { Upload, Download };

struct Result {
  core::Duration elapsed{};
  std::uint64_t done = 0;
  std::uint64_t failed = 0;
  std::uint64_t corrupt = 0;
  std::uint64_t frames = 0;
  core::Duration busy{};
  std::size_t allocations = 0;
  bool stalled = false;
};

class Run {
 public:
  Run(std::uint32_t bitrate, Direction direction, Polling polling, int objects)
      : bus_(bitrate),
        client_end_(bus_.connect()),
        server_end_(bus_.connect()),
        channel_{canopen::SdoChannelConfig{1, 1, kRequestCob, kResponseCob}},
        client_(channel_, canopen::SdoTiming{100ms, 2}),
        server_({kRequestCob, kResponseCob}, object_),
        wire_(bitrate),
        direction_(direction),
        polling_(polling),
        objects_(objects) {
    client_end_->open();
    server_end_->open();
    for (std::size_t i = 0; i < kObjectSize; ++i) data_[i] = pattern(i);
    ids_.reserve(SdoClient::kQueueDepth);
  }

  Result go() {
    Result r;
    const drivegate::test::AllocationScope scope;
    core::TimePoint now{};
    core::TimePoint tick{};
    const bool ticks = !polling_.client_on_arrival || !polling_.server_on_arrival;
    for (;;) {
      const bool at_tick = ticks && now >= tick;
      if (at_tick) tick += kCycle;
      // The drive first, then the master: CanopenBus steps its simulated drives before it receives.
      if (polling_.server_on_arrival || at_tick) step_server(now);
      if (polling_.client_on_arrival || at_tick) step_client(now, r);
      if (r.done + r.failed == static_cast<std::uint64_t>(objects_)) break;
      const core::TimePoint next = std::min(ticks ? tick : core::TimePoint::max(), wire_.next_after(now));
      if (next == core::TimePoint::max()) {
        r.stalled = true;  // nothing due and nothing on the wire: the engines lost a transfer
        break;
      }
      now = next;
    }
    r.allocations = scope.count();
    r.corrupt += object_.corrupt();
    const auto stats = bus_.stats();
    r.frames = stats.frames;
    r.busy = stats.busy;
    return r;
  }

 private:
  void step_server(core::TimePoint now) {
    for (std::size_t got = server_end_->receive(rx_, now), i = 0; i < got; ++i) server_.on_frame(rx_[i], now);
    server_.poll(now, tx_);
    flush(*server_end_, now);
  }
  void step_client(core::TimePoint now, Result& r) {
    for (std::size_t got = client_end_->receive(rx_, now), i = 0; i < got; ++i) client_.on_frame(rx_[i], now);
    collect(now, r);
    while (submitted_ < objects_ && client_.pending(0) < SdoClient::kQueueDepth) {
      const SdoRequestId id =
          direction_ == Direction::Upload ? client_.read(0, kObject) : client_.write_from(0, kObject, data_);
      ids_.push_back(id);
      ++submitted_;
    }
    client_.poll(now, tx_);
    flush(*client_end_, now);
  }
  // Results in submission order; the run's time is when the last one is seen.
  void collect(core::TimePoint now, Result& r) {
    std::size_t taken = 0;
    for (; taken < ids_.size(); ++taken) {
      const SdoRequestId id = ids_[taken];
      const SdoStatus status = client_.result(id).status;
      if (status == SdoStatus::Queued || status == SdoStatus::InFlight) break;
      if (status == SdoStatus::Done) {
        ++r.done;
        const auto bytes = client_.data(id);
        if (direction_ == Direction::Upload && !std::equal(bytes.begin(), bytes.end(), data_.begin(), data_.end()))
          ++r.corrupt;
      } else {
        ++r.failed;
      }
      client_.take(id);
      r.elapsed = now - core::TimePoint{};
    }
    ids_.erase(ids_.begin(), ids_.begin() + static_cast<std::ptrdiff_t>(taken));
  }
  void flush(canopen::InprocEndpoint& end, core::TimePoint now) {
    for (; !tx_.empty(); tx_.pop())
      if (end.send(tx_.front(), now) == canopen::SendResult::Sent) wire_.sent(now);
  }

  canopen::InprocBus bus_;
  std::unique_ptr<canopen::InprocEndpoint> client_end_;
  std::unique_ptr<canopen::InprocEndpoint> server_end_;
  std::array<canopen::SdoChannelConfig, 1> channel_;
  SdoClient client_;
  BufferObject object_;
  canopen::sim::SdoServer server_;
  WireSchedule wire_;
  Direction direction_;
  Polling polling_;
  int objects_;
  int submitted_ = 0;
  std::vector<SdoRequestId> ids_;
  std::array<std::uint8_t, kObjectSize> data_{};
  std::array<CanFrame, 16> rx_{};
  canopen::TxQueue tx_;
};

std::optional<int> parse_objects(int argc, char** argv) {
  if (argc == 1) return 400;
  if (argc != 3 || std::string_view(argv[1]) != "--objects") return std::nullopt;
  const std::string_view s(argv[2]);
  int v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc{} || end != s.data() + s.size() || v <= 0) return std::nullopt;
  return v;
}

int run(int argc, char** argv) {
  const std::optional<int> objects = parse_objects(argc, argv);
  if (!objects) {
    std::fprintf(stderr, "usage: bench_canopen_sdo [--objects N (default 400)]\n");
    return 2;
  }
  std::printf("bench_canopen_sdo: segmented SDO transfers of one %zu-byte object, back to back, one client channel\n"
              "  and one server on the bit-rate-emulating in-process bus; %d objects per row; virtual time\n"
              "  (deterministic: the same figures on every run)\n",
              kObjectSize, *objects);
  std::printf("  ideal = %zu B x bitrate / (%u frames x %u bits): per object an initiate request and response\n"
              "          and %u segment requests and responses (ceil(%zu / 7)), every SDO frame DLC 8 =\n"
              "          frame_bits(8) = %u bits (wire/bit_timing.hpp, worst-case stuffing)\n",
              kObjectSize, kFramesPerObject, canopen::frame_bits(8), kSegments, kObjectSize,
              canopen::frame_bits(8));
  std::printf("  raw   = bitrate / 8: the payload rate of a wire that carried nothing but data bytes\n");
  std::printf("  polling: on arrival = client and server run whenever a frame arrives (the protocol alone);\n"
              "           1 ms cycle = both run once per 1 ms cycle (drivegated with its simulated drives);\n"
              "           1 ms cycle, drive on arrival = the client once per 1 ms cycle, the server answering\n"
              "           the moment a request arrives (drivegated with a drive that answers at once)\n\n");
  std::printf("%8s  %-9s %-29s %9s %9s %8s %7s %10s %9s %9s %6s %6s\n", "kbit/s", "direction", "polling", "bytes/s",
              "ideal B/s", "of ideal", "of raw", "frames/obj", "wire busy", "ms/object", "failed", "allocs");
  bool healthy = true;
  for (const std::uint32_t bitrate : {125'000U, 500'000U, 1'000'000U}) {
    const double ideal = static_cast<double>(kObjectSize) * bitrate / kBitsPerObject;
    const double raw = bitrate / 8.0;
    for (const Direction direction : {Direction::Upload, Direction::Download}) {
      for (const Polling& polling : kPollings) {
        Run run(bitrate, direction, polling, *objects);
        const Result r = run.go();
        const double seconds = std::chrono::duration<double>(r.elapsed).count();
        const double rate = seconds > 0.0 ? static_cast<double>(r.done * kObjectSize) / seconds : 0.0;
        std::printf("%8u  %-9s %-29s %9.0f %9.0f %7.1f%% %6.1f%% %10.2f %8.1f%% %9.3f %6llu %6zu\n", bitrate / 1000,
                    direction == Direction::Upload ? "upload" : "download", polling.name, rate, ideal,
                    100.0 * rate / ideal, 100.0 * rate / raw,
                    static_cast<double>(r.frames) / static_cast<double>(*objects),
                    seconds > 0.0 ? 100.0 * std::chrono::duration<double>(r.busy).count() / seconds : 0.0,
                    seconds * 1000.0 / static_cast<double>(*objects), static_cast<unsigned long long>(r.failed),
                    r.allocations);
        if (r.stalled || r.failed > 0 || r.corrupt > 0) {
          healthy = false;
          std::printf("          ^ %s%llu corrupt transfers: the figure is not valid\n",
                      r.stalled ? "stalled, " : "", static_cast<unsigned long long>(r.corrupt));
        }
      }
    }
  }
  return healthy ? 0 : 1;
}

}  // namespace
}  // namespace drivegate::bench

int main(int argc, char** argv) { return drivegate::bench::run(argc, argv); }
