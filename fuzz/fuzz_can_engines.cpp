// The master engines and a simulated slave on one virtual bus, with the fuzz input injecting
// frames and moving virtual time (adapters/canopen/README.md, engine conventions). The engines talk
// to each other as on a real bus (an NMT start, SDO transfers kept in flight, SYNC, PDOs,
// heartbeats, guarding, EMCY), so injected frames land in the middle of real transfers. What
// counts: crashes and sanitizer reports; every engine must count and drop what it does not expect.
//
// Input: byte 0 picks the slave's persona; then records of
//   [id lo] [id hi: bit 7 extended, bit 6 remote, bits 0-5 id bits 8-13] [dlc (low nibble, 0..15)
//   | time step (high nibble, index into kSteps)] [min(dlc, 8) data bytes, none for a remote frame]
// Ids above 7FFh and DLCs above 8 are deliberate: frames that cannot exist must be dropped too.
#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "adapters/canopen/master/emcy_consumer.hpp"
#include "adapters/canopen/master/nmt_master.hpp"
#include "adapters/canopen/master/pdo.hpp"
#include "adapters/canopen/master/sdo_client.hpp"
#include "adapters/canopen/master/tx_queue.hpp"
#include "adapters/canopen/sim/persona.hpp"
#include "adapters/canopen/sim/slave_config.hpp"
#include "adapters/canopen/sim/slave_node.hpp"
#include "adapters/canopen/wire/cob_id.hpp"
#include "config/plan.hpp"

namespace {

using namespace drivegate;
using namespace drivegate::canopen;
using namespace std::chrono_literals;
using cia402::DataType;

constexpr NodeId kSlave = 1;     // the simulated drive
constexpr NodeId kGuarded = 2;   // registered with guarding and EMCY, never answers
constexpr std::array<core::Duration, 16> kSteps{0ms, 1ms, 2ms, 5ms, 10ms, 20ms, 50ms, 100ms,
                                                 200ms, 300ms, 500ms, 1s, 2s, 5s, 10s, 60s};

config::PdoEntrySpec entry(std::uint16_t index, DataType type) {
  return {{index, 0}, static_cast<std::uint8_t>(8 * cia402::size_of(type)), type};
}

config::PdoSpec pdo(int number, std::vector<config::PdoEntrySpec> entries) {
  config::PdoSpec p;
  p.number = number;
  p.transmission_type = 1;
  p.entries = std::move(entries);
  return p;
}

// The reference personas as tests/canopen_sim builds them (sim_test_support.hpp); the SD6 takes
// the device profile's PDO maps (stoeber-sd6-canopen.md §6.6: fixed PDO count).
sim::SlaveNodeConfig slave_config(std::uint8_t pick) {
  const std::vector<config::PdoSpec> rpdos{pdo(1, {entry(0x6040, DataType::U16), entry(0x6060, DataType::I8)})};
  const std::vector<config::PdoSpec> tpdos{pdo(1, {entry(0x6041, DataType::U16), entry(0x6061, DataType::I8)})};
  cia402::sim::DriveModelConfig drive;
  switch (pick % 4) {
    case 0:
      drive.supported_modes = {1, 3, 4, 6, 7, 8};
      return sim::make_slave_config(kSlave, sim::persona_for("akd"), drive);
    case 1:
      drive.supported_modes = {1, 2, 3, 4, 6};
      return sim::make_slave_config(kSlave, sim::persona_for("nord-sk500p"), drive);
    case 2:
      drive.supported_modes = {1, 3, 6};
      return sim::make_slave_config(kSlave, sim::persona_for("stoeber-sd6"), drive, rpdos, tpdos);
    default: return sim::make_slave_config(kSlave, sim::persona_for("generic"), drive, rpdos, tpdos);
  }
}

PdoLayout layout(std::initializer_list<cia402::ObjectDef> defs) {
  PdoLayout l;
  for (const auto& d : defs) l.add(d, static_cast<std::uint8_t>(8 * cia402::size_of(d.type)));
  return l;
}

class Bus {
 public:
  explicit Bus(std::uint8_t persona)
      : slave_(slave_config(persona)),
        sdo_(std::array{SdoChannelConfig{kSlave, 1, 0, 0}}, SdoTiming{}),
        nmt_(NmtMasterConfig{}, std::array{NmtNodeConfig{kSlave, Watch::Heartbeat, 300ms, 100ms, 3},
                                           NmtNodeConfig{kGuarded, Watch::Guarding, 300ms, 100ms, 3}}),
        emcy_(kEmcyNodes),
        sync_(cob::kSync, 10ms) {
    const std::array rx{RpdoConfig{cob::rpdo(0, kSlave), layout({cia402::obj::kControlword}), 1, {}, 0}};
    const std::array tx{TpdoConfig{cob::tpdo(0, kSlave), layout({cia402::obj::kStatusword}), 1, {}}};
    pdos_.configure(rx, tx);
    pdos_.enable(true, now_);
    nmt_.watch(kGuarded, now_);
    sync_.start(now_);
  }

  void inject(const CanFrame& f) {
    slave_.on_frame(f, now_);
    to_master(f);
  }

  void advance(core::Duration step) {
    now_ += step;
    // A few rounds at the same time: responses produce requests (SDO segments, guard replies).
    for (int round = 0; round < 4; ++round) {
      if (sync_.poll(now_, master_tx_)) pdos_.after_sync(now_, master_tx_);
      pdos_.poll(now_, master_tx_);
      keep_sdo_busy();
      sdo_.poll(now_, master_tx_);
      nmt_.poll(now_, master_tx_);
      slave_.step(now_, slave_tx_);
      const bool quiet = master_tx_.empty() && slave_tx_.empty();
      for (; !master_tx_.empty(); master_tx_.pop()) slave_.on_frame(master_tx_.front(), now_);
      for (; !slave_tx_.empty(); slave_tx_.pop()) to_master(slave_tx_.front());
      handle_events();
      if (quiet) break;
    }
  }

 private:
  static constexpr std::array kFields{EmcyField{3, "event"}, EmcyField{4, "cause"}};
  static constexpr std::array kTexts{cia402::FaultText{0x7500, "communication"}};
  static constexpr std::array kEmcyNodes{EmcyNodeConfig{kSlave, kTexts, kFields, true},
                                         EmcyNodeConfig{kGuarded, {}, {}, false}};

  void to_master(const CanFrame& f) {
    sdo_.on_frame(f, now_);
    nmt_.on_frame(f, now_);
    emcy_.on_frame(f, now_);
    pdos_.on_frame(f, now_);
  }

  // One request in flight at all times, cycling through expedited and segmented transfers.
  void keep_sdo_busy() {
    if (sdo_.pending(0) != 0) return;
    if (request_ != kNoSdoRequest) {
      (void)sdo_.data(request_);
      sdo_.take(request_);
    }
    static constexpr std::array<std::uint8_t, 12> kName{'d', 'r', 'i', 'v', 'e', 'g', 'a', 't', 'e', '-', 'f', 'z'};
    switch (requests_++ % 4) {
      case 0: request_ = sdo_.read(0, {0x1018, 1}, 4); break;
      case 1: request_ = sdo_.read(0, {0x1008, 0}); break;  // device name: a segmented upload
      case 2: request_ = sdo_.write(0, {0x6060, 0}, 3, 1); break;
      default: request_ = sdo_.write_from(0, {0x2000, 0}, kName); break;
    }
  }

  void handle_events() {
    NmtEvent e;
    while (nmt_.next_event(e)) {
      if (e.kind == NmtEventKind::BootUp && e.node == kSlave) {
        nmt_.command(NmtCommand::Start, kSlave, master_tx_);
        nmt_.watch(kSlave, now_);
        emcy_.reset(kSlave);
        sdo_.reset_channel(0);
        request_ = kNoSdoRequest;
      }
    }
    EmcyReport r;
    while (emcy_.next_report(r)) {
    }
  }

  core::TimePoint now_{std::chrono::seconds(1000)};
  sim::SlaveNode slave_;
  SdoClient sdo_;
  NmtMaster nmt_;
  EmcyConsumer emcy_;
  NodePdos pdos_;
  SyncProducer sync_;
  TxQueue master_tx_;
  TxQueue slave_tx_;
  SdoRequestId request_ = kNoSdoRequest;
  unsigned requests_ = 0;
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  // Two TxQueues and the slave are large: on the heap, not the fuzzer's stack.
  auto bus = std::make_unique<Bus>(data[0]);
  std::size_t at = 1;
  while (at + 3 <= size) {
    const std::uint8_t lo = data[at];
    const std::uint8_t hi = data[at + 1];
    const std::uint8_t len = data[at + 2];
    at += 3;
    CanFrame f;
    f.extended = (hi & 0x80) != 0;
    f.remote = (hi & 0x40) != 0;
    f.id = static_cast<std::uint32_t>(lo) | (static_cast<std::uint32_t>(hi & 0x3F) << 8);
    if (f.extended) f.id |= 0x1000000;
    f.dlc = static_cast<std::uint8_t>(len & 0x0F);
    if (!f.remote) {
      for (std::size_t i = 0; i < 8 && i < f.dlc && at < size; ++i) f.data[i] = data[at++];
    }
    bus->inject(f);
    bus->advance(kSteps[len >> 4]);
  }
  return 0;
}
