#pragma once
// The device side of connection management (CMDEV) for the simulator, sans I/O, one IO AR at a
// time [IEC 61158-6-10 §4.10.3, §5.1.2; CMRPC/CMDEV checks as the PNIOStatus texts name them]:
//
//   Connect   the request is checked (IOCARSingle, exactly one input and one output IOCR of RT
//             class 1, the AlarmCR) and its expected submodules compared with the device model:
//             a slot the model lacks is "no module", another module ident "wrong module", a
//             missing or other submodule "no submodule" / "wrong submodule" in the ModuleDiffBlock;
//             the AR is set up anyway (the controller decides). The application sees the
//             Connect first (CmServerApp::on_connect) and may refuse it. A Connect for the AR UUID that
//             already exists aborts that AR first (the controller restarted); another AR UUID
//             while one runs is refused with CMRPC "Out of AR Resources".
//   records   IODWrite/IODRead for the running AR go to the CmServerApp with the API, slot,
//             subslot and index (a slot/subslot the model lacks: PNIORW "invalid slot/subslot").
//   PrmEnd    answered; then the device calls the controller's RPC server (its IP, port
//             controller_port) with IOXControlReq ApplicationReady, retransmitted per `rpc`;
//             the controller's OK response starts data exchange, a refusal or timeout aborts the AR.
//   Release   answered; the AR ends.
//
// Repeated requests are answered from the cache, pings with the cache or nocall (cm_rpc.hpp).
// Nothing allocates after construction.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "adapters/profinet/controller/cm_rpc.hpp"
#include "adapters/profinet/wire/blocks_control.hpp"
#include "adapters/profinet/wire/blocks_record.hpp"
#include "adapters/profinet/wire/rpc_connect.hpp"
#include "core/fixed_string.hpp"

namespace drivegate::profinet {

// What the device really has: its slots, each with a module and its submodules.
struct CmModelSubmodule {
  std::uint16_t subslot = 1;
  std::uint32_t ident = 0;
};
struct CmModelSlot {
  std::uint32_t api = 0;
  std::uint16_t slot = 0;
  std::uint32_t module_ident = 0;
  std::span<const CmModelSubmodule> submodules{};
};

struct CmServerConfig {
  PnioObject object{};         // the device's (the object UUID of the calls to it)
  MacAddress mac{};            // ARBlockRes CMResponderMacAdd
  Uuid activity{};             // the device's activity for its ApplicationReady calls
  std::span<const CmModelSlot> slots{};  // must outlive the server
  RpcTiming rpc{};
  std::uint16_t controller_port = kRpcUdpPort;  // where the controller's RPC server listens
  std::uint32_t boot_time = 1;
  ByteOrder order = ByteOrder::Little;  // of the device's own calls
};

// [sim] The device's LocalAlarmReference, answered in the AlarmCRBlockRes: one AR at a time.
inline constexpr std::uint16_t kDeviceAlarmReference = 1;

enum class CmServerState : std::uint8_t {
  NoAr,
  Parameterising,    // Connect answered, records and PrmEnd expected
  ApplicationReady,  // PrmEnd answered, the ApplicationReady call runs
  DataExchange,
};
std::string_view to_string(CmServerState s) noexcept;

// The IOCRs of a Connect the server is about to accept, with the FrameIDs it answers.
struct CmArSetup {
  const ConnectRequestView& request;
  const IocrBlockReqView& input;
  const IocrBlockReqView& output;
  std::uint16_t input_frame_id = 0;
  std::uint16_t output_frame_id = 0;
};

// The simulated device's application: record contents and AR events.
class CmServerApp {
 public:
  // A Connect that passed the server's checks, before its expected submodules are compared with
  // the model: the application may fit the model to it (the slots' spans it owns) and sets up its
  // cyclic data. A status other than OK refuses the Connect with it (no AR).
  virtual PnioStatus on_connect(const CmArSetup& setup) noexcept = 0;
  // A write for the running AR; the PNIOStatus of the answer (OK: zero).
  virtual PnioStatus on_record_write(const RecordReqHeader& h, std::span<const std::uint8_t> data) noexcept = 0;
  // A read: up to `into.size()` bytes (the controller's RecordDataLength, at most what fits one
  // datagram) into `into`, their count into `length`.
  virtual PnioStatus on_record_read(const RecordReqHeader& h, std::span<std::uint8_t> into,
                                    std::size_t& length) noexcept = 0;
  // The AR went to `state`; `why` says why when it ended other than by Release.
  virtual void on_ar_state(CmServerState state, std::string_view why) noexcept = 0;

 protected:
  CmServerApp() = default;
  CmServerApp(const CmServerApp&) = default;
  CmServerApp& operator=(const CmServerApp&) = default;
  ~CmServerApp() = default;
};

struct CmServerCounters {
  RpcCounters rpc{};
  std::uint64_t connects = 0, connects_refused = 0, aborts = 0, releases = 0;
  std::uint64_t writes = 0, reads = 0, records_refused = 0;
};

class CmServer {
 public:
  static constexpr std::size_t kMaxDiffModules = 16;
  static constexpr std::size_t kMaxDiffSubmodules = 32;

  CmServer(const CmServerConfig& config, CmServerApp& app) noexcept;

  void poll(core::TimePoint now, CmOutbox& out) noexcept;
  // When poll() has something to do (the ApplicationReady call's next send or its end).
  [[nodiscard]] core::TimePoint next_deadline() const noexcept { return ready_call_.next_deadline(); }
  // The device ends the running AR itself (its watchdog, an injected fault): no word to the
  // controller; abort_reason() says `why`. Nothing happens without an AR.
  void abort_ar(std::string_view why) noexcept;
  // A datagram arrived at `socket` (Server: the controller's calls; Client: the answers to the
  // device's ApplicationReady call) from `from`.
  void on_datagram(std::span<const std::uint8_t> datagram, const UdpEndpoint& from, CmSocket socket,
                   core::TimePoint now, CmOutbox& out) noexcept;

  [[nodiscard]] CmServerState state() const noexcept { return state_; }
  [[nodiscard]] const Uuid& ar_uuid() const noexcept { return ar_.ar_uuid; }
  [[nodiscard]] std::uint16_t session_key() const noexcept { return ar_.session_key; }
  // Why the last AR ended other than by Release (empty after a Release).
  [[nodiscard]] std::string_view abort_reason() const noexcept { return abort_reason_.view(); }
  [[nodiscard]] const CmServerCounters& counters() const noexcept { return counters_; }

 private:
  struct Ar {
    Uuid ar_uuid{};
    std::uint16_t session_key = 0;
    Uuid initiator_object{};
    UdpEndpoint controller{};
  };

  void on_request(std::span<const std::uint8_t> datagram, const UdpEndpoint& from, core::TimePoint now,
                  CmOutbox& out) noexcept;
  void on_connect(std::span<const std::uint8_t> datagram, const UdpEndpoint& from, CmOutbox& out) noexcept;
  void on_record(const RpcHeader& h, const NdrRequest& ndr, CmOutbox& out) noexcept;
  void on_control(const RpcHeader& h, const NdrRequest& ndr, core::TimePoint now, CmOutbox& out) noexcept;
  void on_ready_response(std::span<const std::uint8_t> datagram) noexcept;
  // Compares the expected submodules with the model; the differences go into the diff arrays.
  void compare(const ConnectRequestView& c) noexcept;
  [[nodiscard]] const CmModelSlot* find_slot(std::uint32_t api, std::uint16_t slot) const noexcept;
  [[nodiscard]] bool has_subslot(std::uint32_t api, std::uint16_t slot, std::uint16_t subslot) const noexcept;
  void set_state(CmServerState s, std::string_view why = {}) noexcept;
  void abort(std::string_view why) noexcept;

  CmServerConfig config_;
  CmServerApp& app_;
  CmServerCounters counters_{};
  RpcResponder responder_;
  RpcCall ready_call_;
  CmServerState state_ = CmServerState::NoAr;
  Ar ar_{};
  std::uint32_t sequence_ = 0;  // of the device's next call
  std::array<ModuleDiffModule, kMaxDiffModules> diff_modules_{};
  std::array<std::uint32_t, kMaxDiffModules> diff_module_api_{};
  std::array<ModuleDiffSubmodule, kMaxDiffSubmodules> diff_submodules_{};
  std::array<ModuleDiffApi, kMaxDiffModules> diff_apis_{};
  std::size_t diff_module_count_ = 0;
  std::size_t diff_submodule_count_ = 0;
  std::size_t diff_api_count_ = 0;
  std::array<std::uint8_t, kMaxPnioArgs> record_{};
  core::FixedString<200> abort_reason_{};
};

}  // namespace drivegate::profinet
