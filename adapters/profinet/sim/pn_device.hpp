#pragma once
// One simulated PROFINET IO device, sans-I/O like the engines it is built of (DESIGN.md §2 rule 1):
//
//   DcpResponder   identify, set name / IP, signal (dcp_responder.hpp)
//   CmServer       Connect / Write / Read / Control / Release, ApplicationReady (cm_server.hpp)
//   cyclic data    an RtProvider for the input CR and an RtConsumer for the output CR
//                  (RtSide::Device), set up from the Connect; the consumer's data-hold watchdog
//                  aborts the AR [IEC 61158-6-10 §4.7.2.1.2]
//   alarms         an AlarmSender on the AR's alarm CR (alarm_sender.hpp), started with the
//                  Connect from its AlarmCRBlockReq (timeout, retries, the controller's alarm
//                  reference, tags) and gone when the AR ends; an alarm CR that aborts (no ACK
//                  after every retry, or the controller's ERR-RTA-PDU) aborts the AR
//   a persona      the slots, records and cycle behaviour (pn_persona.hpp)
//
// on_frame() takes what the device's port receives, on_datagram() what its UDP sockets receive
// (Server: 34964; Client: the answers to its ApplicationReady call), poll() gives one frame per call
// into the caller's buffer and the datagrams into the caller's CmOutbox, next_deadline() says when
// to call again. The time is a parameter.
//
// The Connect's submodules must have the data lengths the persona gives them (else the Connect is
// refused: ExpectedSubmoduleBlockReq, SubmoduleDataLength), its CRs must not be faster than the
// persona's min_update_time() (IOCRBlockReq, ReductionRatio), its AlarmCR must have a usable
// RTATimeoutFactor and RTARetries (AlarmCRBlockReq), and its IOCRs must lay out as
// compute_csdu_layout does (else IOCRBlockReq, DataLength / FrameOffset) [sim: a real device takes
// any offsets the controller chooses; ours are the only layout our controller builds]. The cyclic
// engines start with the accepted Connect; the input data's IOPS turn good once the AR is in data
// exchange (ApplicationReady answered).
//
// Fault injection: power_loss() / power_return() (the AR is gone without a word, the temporary
// name and IP are lost, the persona starts over), abort_ar(), losing the next received or sent
// cyclic frames, send_alarm(). Nothing allocates after construction.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

#include "adapters/profinet/controller/rt_cyclic.hpp"
#include "adapters/profinet/sim/alarm_sender.hpp"
#include "adapters/profinet/sim/cm_server.hpp"
#include "adapters/profinet/sim/dcp_responder.hpp"
#include "adapters/profinet/sim/pn_persona.hpp"

namespace drivegate::profinet {

struct PnDeviceConfig {
  DcpResponderConfig dcp{};  // MAC, NameOfStation, IP suite, vendor and device ID, instance
  Uuid activity{};           // of the device's own calls (ApplicationReady)
  RpcTiming rpc{};
  // The persona's cycle while no AR runs (the AKD's fastest update time, digest §2).
  core::Duration idle_period = std::chrono::milliseconds(16);
};

struct PnDeviceCounters {
  std::uint64_t cycles = 0;              // persona cycles with an AR
  std::uint64_t connects_refused = 0;    // by the device's checks (lengths, layout)
  std::uint64_t watchdog_aborts = 0;     // the output CR's data hold time passed
  std::uint64_t alarm_cr_aborts = 0;     // the alarm CR aborted (no ACK, or the controller's ERR)
  std::uint64_t rx_lost = 0, tx_lost = 0;  // cyclic frames dropped by the loss injection
  std::uint64_t rx_powered_off = 0;      // frames and datagrams that found the device off
};

class PnDevice final : private CmServerApp {
 public:
  // Throws std::invalid_argument as DcpResponder does for a bad name, IP suite or TypeOfStation.
  PnDevice(const PnDeviceConfig& config, PnPersona& persona);

  // A received frame (DCP, this AR's output CR); false for traffic not for the device.
  bool on_frame(std::span<const std::uint8_t> frame, core::TimePoint now) noexcept;
  // A received datagram at `socket`.
  void on_datagram(std::span<const std::uint8_t> datagram, const UdpEndpoint& from, CmSocket socket,
                   core::TimePoint now, CmOutbox& out) noexcept;
  // Runs what is due; returns the length of one frame written into `frame` (call until 0).
  std::size_t poll(core::TimePoint now, std::span<std::uint8_t> frame, CmOutbox& out) noexcept;
  [[nodiscard]] core::TimePoint next_deadline() const noexcept;

  // --- fault injection ---
  void power_loss() noexcept;
  void power_return(core::TimePoint now) noexcept;
  [[nodiscard]] bool powered() const noexcept { return powered_; }
  // Aborts the running AR as the device would on an internal error (the controller sees its
  // output frames ignored and the input CR silent).
  void abort_ar(std::string_view why) noexcept;
  // Drops the next `n` cyclic frames received / sent (counted rx_lost / tx_lost).
  void lose_rx_frames(std::uint32_t n) noexcept { lose_rx_ = n; }
  void lose_tx_frames(std::uint32_t n) noexcept { lose_tx_ = n; }
  // Queues an alarm on the running AR's alarm CR (AlarmSender::send: the specifier's sequence
  // number is the sender's); false without an AR or when the sender refuses it.
  bool send_alarm(const AlarmNotification& n) noexcept { return alarms_ && alarms_->send(n); }

  [[nodiscard]] const MacAddress& mac() const noexcept { return dcp_.mac(); }
  [[nodiscard]] std::uint32_t ip() const noexcept;  // the current IP address (0: none)
  [[nodiscard]] DcpResponder& dcp() noexcept { return dcp_; }
  [[nodiscard]] std::string_view name_of_station() const noexcept { return dcp_.name_of_station(); }
  [[nodiscard]] const CmServer& cm() const noexcept { return *cm_; }
  [[nodiscard]] CmServerState ar_state() const noexcept { return cm_->state(); }
  // Why the last AR ended other than by Release.
  [[nodiscard]] std::string_view abort_reason() const noexcept { return cm_->abort_reason(); }
  [[nodiscard]] const RtConsumer* output_cr() const noexcept { return consumer_ ? &*consumer_ : nullptr; }
  [[nodiscard]] const RtProvider* input_cr() const noexcept { return provider_ ? &*provider_ : nullptr; }
  [[nodiscard]] const AlarmSender* alarm_cr() const noexcept { return alarms_ ? &*alarms_ : nullptr; }
  [[nodiscard]] PnPersona& persona() noexcept { return persona_; }
  [[nodiscard]] const PnDeviceCounters& counters() const noexcept { return counters_; }

 private:
  // CmServerApp
  PnioStatus on_connect(const CmArSetup& setup) noexcept override;
  PnioStatus on_record_write(const RecordReqHeader& h, std::span<const std::uint8_t> data) noexcept override;
  PnioStatus on_record_read(const RecordReqHeader& h, std::span<std::uint8_t> into, std::size_t& length) noexcept override;
  void on_ar_state(CmServerState state, std::string_view why) noexcept override;

  // The AR's submodule list and the two IOCR configs from a Connect; a refusal's status.
  PnioStatus set_up_cyclic(const CmArSetup& setup) noexcept;
  // 0 when the IOCR's C_SDU length and frame offsets are the engine's `placements`, else the
  // IOCRBlockReq field that differs (the PNIOStatus ErrorCode2 of the refusal).
  [[nodiscard]] std::uint8_t iocr_mismatch(const IocrBlockReqView& v, std::span<const IoPlacement> placements) const noexcept;
  // Ends the AR's cyclic engines and its alarm CR.
  void stop_ar_engines() noexcept;
  void run_cycle(core::Duration dt) noexcept;
  CmServerConfig cm_config() const noexcept;

  PnDeviceConfig config_;
  PnPersona& persona_;
  DcpResponder dcp_;
  std::optional<CmServer> cm_;
  std::uint32_t boot_time_ = 1;
  bool powered_ = true;
  core::TimePoint now_{};  // of the call in progress (the cyclic engines start with the Connect)
  core::TimePoint idle_next_{};
  bool idle_started_ = false;

  // The running AR's cyclic data.
  std::array<IoSubmodule, kMaxRtSubmodules> submodules_{};
  std::array<PnSubmoduleIo, kMaxRtSubmodules> io_{};
  std::array<bool, kMaxRtSubmodules> proper_{};  // the model has the submodule the Connect expects
  std::size_t submodule_count_ = 0;
  std::optional<RtProvider> provider_;
  std::optional<RtConsumer> consumer_;
  std::optional<AlarmSender> alarms_;

  std::uint32_t lose_rx_ = 0, lose_tx_ = 0;
  PnDeviceCounters counters_{};
};

}  // namespace drivegate::profinet
