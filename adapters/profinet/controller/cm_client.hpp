#pragma once
// The controller side of one IO AR's connection management (CMCTL), sans I/O [IEC 61158-6-10
// §4.10.3 "RPC", §5.1.2 IODConnect/IODWrite/IODRead/IODControl/IODRelease; the AKD's start-up,
// digest akd-profinet-profidrive.md §24 steps 5-8]:
//
//   Connecting      Connect (ARBlockReq, input and output IOCR of RT class 1, AlarmCR, the
//                   expected submodules); the response's AR UUID and session key must be ours and
//                   both IOCRs and the AlarmCR answered. A ModuleDiffBlock is kept as text per
//                   slot (module_diff()); a wrong or missing module/submodule, or one locked by
//                   another AR, fails the start-up unless accept_module_diff (then the AR runs
//                   with what matches). "Application ready pending" and diagnosis bits are shown,
//                   not refused.
//   Parameterising  the configured record writes, in order, one at a time.
//   PrmEnd          IODControlReq PrmEnd.
//   WaitApplicationReady  the device calls the controller's RPC server (CmSocket::Server) with
//                   IOXControlReq ApplicationReady; it is answered (OK for our AR UUID and session
//                   key, else CMRPC "AR UUID unknown" / CMCTL "State conflict"). One that arrives
//                   before the PrmEnd response (UDP may reorder) is answered and remembered.
//   DataExchange    record reads/writes of the caller run here, one at a time.
//   Releasing       IODReleaseReq; then Released.
//   Failed          reason() is one line: the phase, what went wrong, the PNIOStatus decoded, the
//                   module-diff report; failed_in() the state the AR was in. After a refusal
//                   once the AR exists, the client releases it before it ends in Failed.
//
// Record requests (submit_read/submit_write) are taken from Connecting to DataExchange into a
// fixed queue of kRecordQueueDepth, run one at a time in DataExchange, and each gets exactly one
// reply through the CmRecordListener: done, refused by the device (its PNIOStatus), failed (RPC
// timeout, reject, malformed answer), or aborted (the AR ended first).
//
// Datagrams: on_datagram() takes every datagram from the device's address, on either socket; the
// engine writes what it sends into the caller's CmOutbox. Nothing allocates after construction.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "adapters/profinet/controller/cm_rpc.hpp"
#include "adapters/profinet/wire/blocks_record.hpp"
#include "adapters/profinet/wire/rpc_connect.hpp"
#include "core/clock.hpp"
#include "core/fixed_string.hpp"

namespace drivegate::profinet {

// A record the client writes during parameterisation.
struct CmRecordWrite {
  std::uint32_t api = 0;
  std::uint16_t slot = 0;
  std::uint16_t subslot = 1;
  std::uint16_t index = 0;
  std::span<const std::uint8_t> data{};
};

struct CmClientConfig {
  UdpEndpoint device{0, kRpcUdpPort};
  PnioObject device_object{};  // the object UUID of the calls (vendor and device ID, instance)
  Uuid activity{};             // the controller's activity for its calls on this AR (fresh per AR)
  ByteOrder order = ByteOrder::Little;
  // The AR: AR UUID, session key, initiator MAC and object UUID, station name; the IOCRs (send
  // clock, reduction ratio, watchdog and data-hold factors, frame IDs); the AlarmCR; the expected
  // submodules. Its spans (and the parameters') must outlive the client.
  ConnectRequest connect{};
  std::span<const CmRecordWrite> parameters{};
  RpcTiming rpc{};
  core::Duration application_ready_timeout = std::chrono::seconds(10);  // after the PrmEnd response
  bool accept_module_diff = false;
  std::uint32_t boot_time = 1;  // the controller's RPC server boot time in its responses
};

enum class CmClientState : std::uint8_t {
  Idle,
  Connecting,
  Parameterising,
  PrmEnd,
  WaitApplicationReady,
  DataExchange,
  Releasing,
  Released,
  Failed,
};
std::string_view to_string(CmClientState s) noexcept;

using CmRecordId = std::uint32_t;  // 0 = refused at submit
enum class CmRecordOutcome : std::uint8_t { Done, Refused, Failed, Aborted };
std::string_view to_string(CmRecordOutcome o) noexcept;

struct CmRecordReply {
  CmRecordId id = 0;
  bool write = false;
  CmRecordOutcome outcome = CmRecordOutcome::Done;
  PnioStatus status{};  // Refused: the device's
  std::uint16_t additional_value1 = 0;
  std::uint16_t additional_value2 = 0;
  std::span<const std::uint8_t> data{};  // a read's record data; valid during the call only
  std::string_view text{};               // not Done: why, one line; valid during the call only
};

class CmRecordListener {
 public:
  virtual void on_record_reply(const CmRecordReply& reply) noexcept = 0;

 protected:
  CmRecordListener() = default;
  CmRecordListener(const CmRecordListener&) = default;
  CmRecordListener& operator=(const CmRecordListener&) = default;
  ~CmRecordListener() = default;
};

struct CmClientCounters {
  RpcCounters rpc{};
  std::uint64_t records_submitted = 0, records_done = 0, records_refused = 0, records_failed = 0,
                records_aborted = 0, queue_full = 0;
  std::uint64_t application_ready = 0;  // ApplicationReady requests answered OK
};

class CmClient {
 public:
  static constexpr std::size_t kRecordQueueDepth = 4;
  // Record data that fits one request / response datagram.
  static constexpr std::size_t kMaxRecordData = kMaxPnioArgs - kRecordHeaderSize;

  CmClient(const CmClientConfig& config, CmRecordListener* listener = nullptr) noexcept;

  // Sends the Connect (Idle only; false otherwise).
  bool start(core::TimePoint now, CmOutbox& out) noexcept;
  // Ends the AR: Release when it may exist (after Connect was sent), else Released at once. Queued
  // and running record requests are aborted. Nothing happens in Releasing, Released, Failed.
  void release(core::TimePoint now, CmOutbox& out) noexcept;

  void poll(core::TimePoint now, CmOutbox& out) noexcept;
  // A datagram from the device's address, arrived at `socket`, sent from `from`.
  void on_datagram(std::span<const std::uint8_t> datagram, const UdpEndpoint& from, CmSocket socket,
                   core::TimePoint now, CmOutbox& out) noexcept;

  // 0 when refused (queue full, AR not being set up or running, data or length above
  // kMaxRecordData).
  CmRecordId submit_read(std::uint32_t api, std::uint16_t slot, std::uint16_t subslot, std::uint16_t index,
                         std::size_t max_length = kMaxRecordData) noexcept;
  CmRecordId submit_write(std::uint32_t api, std::uint16_t slot, std::uint16_t subslot, std::uint16_t index,
                          std::span<const std::uint8_t> data) noexcept;

  [[nodiscard]] CmClientState state() const noexcept { return state_; }
  [[nodiscard]] CmClientState failed_in() const noexcept { return failed_in_; }
  [[nodiscard]] std::string_view reason() const noexcept { return reason_.view(); }
  // The device's ModuleDiffBlock, one line per finding ('\n' between), empty when none came.
  [[nodiscard]] std::string_view module_diff() const noexcept { return module_diff_.view(); }
  // From the Connect response (0 before).
  [[nodiscard]] std::uint16_t input_frame_id() const noexcept { return input_frame_id_; }
  [[nodiscard]] std::uint16_t output_frame_id() const noexcept { return output_frame_id_; }
  [[nodiscard]] const ArBlockRes& ar_response() const noexcept { return ar_res_; }
  [[nodiscard]] const AlarmCrBlockRes& alarm_cr_response() const noexcept { return alarm_res_; }
  [[nodiscard]] const CmClientCounters& counters() const noexcept { return counters_; }

 private:
  enum class Call : std::uint8_t { None, Connect, ParameterWrite, PrmEnd, Record, Release };
  struct Record {
    CmRecordId id = 0;
    bool write = false;
    std::uint32_t api = 0;
    std::uint16_t slot = 0;
    std::uint16_t subslot = 0;
    std::uint16_t index = 0;
    std::size_t length = 0;  // write: data bytes; read: the most it takes
    std::array<std::uint8_t, kMaxRecordData> data{};
  };

  CmRecordId submit(bool write, std::uint32_t api, std::uint16_t slot, std::uint16_t subslot, std::uint16_t index,
                    std::size_t length) noexcept;
  [[nodiscard]] RpcHeader next_request(Opnum op) noexcept;
  void begin(Call call, std::size_t size, const RpcHeader& h, core::TimePoint now, CmOutbox& out) noexcept;
  void send_connect(core::TimePoint now, CmOutbox& out) noexcept;
  void send_record(bool write, std::uint32_t api, std::uint16_t slot, std::uint16_t subslot, std::uint16_t index,
                   std::span<const std::uint8_t> data, std::size_t read_length, core::TimePoint now,
                   CmOutbox& out) noexcept;
  void send_control(Call call, core::TimePoint now, CmOutbox& out) noexcept;
  void next_parameter(core::TimePoint now, CmOutbox& out) noexcept;
  void enter_data_exchange(core::TimePoint now, CmOutbox& out) noexcept;
  void start_next_record(core::TimePoint now, CmOutbox& out) noexcept;

  void on_response(std::span<const std::uint8_t> datagram, core::TimePoint now, CmOutbox& out) noexcept;
  void on_connect_response(std::span<const std::uint8_t> datagram, core::TimePoint now, CmOutbox& out) noexcept;
  // Checks a record response against the request; true when OK (data: a read's record data), else
  // `why` holds the reason and `status` the device's PNIOStatus (zero when not the device's).
  bool check_record_response(std::span<const std::uint8_t> datagram, std::span<const std::uint8_t>& data,
                             PnioStatus& status, RecordResHeader& header) noexcept;
  void on_control_response(std::span<const std::uint8_t> datagram, core::TimePoint now, CmOutbox& out) noexcept;
  void on_call_failed(core::TimePoint now, CmOutbox& out) noexcept;
  void on_server_datagram(std::span<const std::uint8_t> datagram, const UdpEndpoint& from, core::TimePoint now,
                          CmOutbox& out) noexcept;

  // Ends in Failed with the reason (printf style), or releases the AR first when `release`.
  __attribute__((format(printf, 4, 5))) void fail(core::TimePoint now, CmOutbox* release_out, const char* fmt,
                                                  ...) noexcept;
  void reply_record(const Record& r, CmRecordOutcome outcome, const PnioStatus& status,
                    std::span<const std::uint8_t> data, std::string_view text, std::uint16_t add1 = 0,
                    std::uint16_t add2 = 0) noexcept;
  void abort_records(std::string_view why) noexcept;

  CmClientConfig config_;
  CmRecordListener* listener_;
  CmClientCounters counters_{};
  RpcCall call_;
  RpcResponder server_;
  Call calling_ = Call::None;
  CmClientState state_ = CmClientState::Idle;
  CmClientState failed_in_ = CmClientState::Idle;
  bool fail_after_release_ = false;
  bool application_ready_seen_ = false;
  std::size_t next_parameter_ = 0;
  std::uint32_t sequence_ = 0;         // of the next RPC call
  std::uint16_t record_sequence_ = 0;  // IODWrite/ReadReqHeader SeqNumber of the next record
  RecordReqHeader record_request_{};   // of the record call in flight
  core::TimePoint ready_deadline_{};
  std::uint16_t input_frame_id_ = 0;
  std::uint16_t output_frame_id_ = 0;
  ArBlockRes ar_res_{};
  AlarmCrBlockRes alarm_res_{};
  std::array<Record, kRecordQueueDepth> records_{};
  std::size_t record_head_ = 0;
  std::size_t record_count_ = 0;
  bool record_running_ = false;
  CmRecordId next_record_id_ = 1;
  core::FixedString<1024> module_diff_{};
  core::FixedString<1400> reason_{};
  core::FixedString<300> scratch_{};  // a record reply's text
};

}  // namespace drivegate::profinet
