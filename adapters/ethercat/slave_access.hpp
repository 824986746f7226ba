#pragma once
// The CiA 402 profile's view of one axis of an EtherCAT slave (profiles/cia402/object_access.hpp):
// mapped objects live in the CyclicExchange's output and input images, at the byte offsets their
// PDO entries give (little-endian, sign-extended per type [ETG.1000.6 PDO mapping; CiA 301 §7.1
// basic data types]); everything else goes over the slave's CoeSdoClient (CoE SDO [ETG.1000.6
// §5.6.2]). Requests are refused (the profile retries next cycle) while the slave is not in OP, so
// the profile never competes with the set-up for the mailbox. CoE emergencies reach the profile as
// fault_report() with the device profile's text. A multi-axis slave (ETG.6010) has one SlaveAccess
// per axis: objects of the profile area (6000h..67FFh) are offset by `axis_offset` x `slave_axis`,
// in the image and over CoE.
//
// Every call happens on the bus thread; nothing here allocates after construction (uploads and
// downloads pass through a fixed buffer per request, so a cancelled request never writes into the
// caller's memory).
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "adapters/ethercat/master/coe_sdo_client.hpp"
#include "adapters/ethercat/master/cyclic_exchange.hpp"
#include "core/clock.hpp"
#include "core/fixed_string.hpp"
#include "profiles/cia402/error_codes.hpp"
#include "profiles/cia402/object_access.hpp"

namespace drivegate::ethercat {

// An object carried in the slave's process data: where it sits in the slave's outputs (output =
// true, SM2) or inputs (SM3), from the PDO entries in assignment order.
struct MappedObject {
  cia402::ObjectId id;
  cia402::DataType type = cia402::DataType::U8;
  bool output = false;
  std::uint16_t offset = 0;  // bytes from the start of the slave's outputs or inputs
};

// An object the gateway writes when it configures the slave, and what it is (for the refusal).
struct EcatOwnedObject {
  cia402::ObjectId id;
  std::string what;  // "set by the EtherCAT bus at every start (start-up write: ...)"
};

class SlaveAccess final : public cia402::ObjectAccess {
 public:
  static constexpr std::size_t kMaxPending = 8;
  static constexpr std::size_t kMaxTransfer = 1024;  // bytes of one upload or download

  // `slave`: its index in the process image; `objects`: its mapped objects (axis 0's numbering);
  // `coe` may be null (no mailbox: every acyclic request is refused).
  SlaveAccess(std::size_t slave, const std::vector<MappedObject>& objects, int slave_axis, std::uint16_t axis_offset,
              CoeSdoClient* coe, std::vector<EcatOwnedObject> owned, std::span<const cia402::FaultText> faults);

  // The bus, once the image exists (before the first begin_cycle()).
  void attach(CyclicExchange* exchange) noexcept { cx_ = exchange; }
  // The slave's CoE client (null: no mailbox), set when the slave is configured.
  void set_coe(CoeSdoClient* coe) noexcept { coe_ = coe; }
  // The device profile's fault texts (the span's data must outlive the access).
  void set_faults(std::span<const cia402::FaultText> faults) noexcept { faults_ = faults; }
  // Called by the bus at the start of each cycle: OP (requests taken), fresh inputs this cycle.
  void begin_cycle(bool operational, bool fresh) noexcept;
  // The slave was re-initialised: its requests are forgotten (the client failed them); a CoE
  // emergency shown as the drive's fault is cleared.
  void forget_requests() noexcept;
  // A CoE emergency of this slave [ETG.1000.6 §5.6.4]: error code 0000h clears the fault report.
  void on_emergency(const CoeEmergency& e) noexcept;
  // Safe stop: the bus writes the controlword itself; the profile's writes to 6040h are dropped.
  void override_controlword(bool on, std::uint16_t value = 0) noexcept;
  // The axis' statusword as the last inputs hold it (0 when 6041h is not mapped).
  [[nodiscard]] std::uint16_t statusword() const noexcept;

  // --- ObjectAccess ---
  // A reference is the object's place in the slave's outputs or inputs (direction, type, byte
  // offset), which the plan fixes at construction; the slave's place in the image is looked up at
  // each access, so references stay valid for the access' lifetime, through a slave's loss and
  // reconfiguration (mapping_generation() never changes).
  [[nodiscard]] cia402::ImageRef resolve(cia402::ObjectId id) const noexcept override;
  [[nodiscard]] std::uint32_t mapping_generation() const noexcept override { return 0; }
  using cia402::ObjectAccess::read;
  using cia402::ObjectAccess::write;
  [[nodiscard]] std::int64_t read(cia402::ImageRef ref) const noexcept override;
  void write(cia402::ImageRef ref, std::int64_t value) noexcept override;
  [[nodiscard]] bool inputs_fresh() const noexcept override { return operational_ && fresh_; }
  cia402::RequestId submit_read(cia402::ObjectDef def) noexcept override;
  cia402::RequestId submit_write(cia402::ObjectDef def, std::int64_t value) noexcept override;
  cia402::RequestId submit_upload(cia402::ObjectId id, std::span<std::uint8_t> into,
                                  std::uint8_t expected_size) noexcept override;
  cia402::RequestId submit_download(cia402::ObjectId id, std::span<const std::uint8_t> data) noexcept override;
  cia402::RequestResult poll(cia402::RequestId id) noexcept override;
  void cancel(cia402::RequestId id) noexcept override;
  [[nodiscard]] std::string_view owner_of(cia402::ObjectId id) const noexcept override;
  void control_lost(std::string_view why) noexcept override;
  [[nodiscard]] cia402::DriveFaultReport fault_report() const noexcept override;

  // The bus takes a loss the profile reported (once): true and the reason, then cleared.
  bool take_control_lost(core::FixedString<200>& why) noexcept {
    if (!control_lost_) return false;
    control_lost_ = false;
    why = lost_why_;
    return true;
  }

  // The object as this axis' slave numbers it (profile area offset per axis).
  [[nodiscard]] cia402::ObjectId on_slave(cia402::ObjectId id) const noexcept;

 private:
  enum class Kind : std::uint8_t { Value, Upload, Download };
  struct Pending {
    CoeSdoId id = 0;
    Kind kind = Kind::Value;
    cia402::DataType type = cia402::DataType::U32;
    bool cancelled = false;              // freed for the caller; taken from the client once it ends
    std::span<std::uint8_t> into{};      // Upload: the caller's buffer
    std::array<std::uint8_t, kMaxTransfer> buffer{};
  };
  Pending* free_slot() noexcept;
  Pending* slot_for(CoeSdoId id) noexcept;
  cia402::RequestId track(Pending* p, CoeSdoId id, Kind kind, cia402::DataType type) noexcept;
  [[nodiscard]] bool can_request() const noexcept { return operational_ && coe_ != nullptr && coe_->valid(); }

  // What the cycle touches first, together (a few cache lines for 64 axes' worth after each sleep).
  std::size_t slave_;
  int slave_axis_;
  std::uint16_t axis_offset_;
  CoeSdoClient* coe_;
  CyclicExchange* cx_ = nullptr;
  bool operational_ = false;
  bool fresh_ = false;
  bool cw_override_ = false;
  bool control_lost_ = false;
  std::uint16_t cw_value_ = 0;
  std::uint16_t cw_place_ = 0xFFFF;  // the controlword's reference (not mapped: FFFFh)
  std::size_t cancelled_ = 0;  // pending_ entries cancelled and not yet taken (begin_cycle() looks only then)
  // resolve()'s open-addressing table of the mapped objects themselves (linear probing, power-of-two
  // size, at most half full; index 0, which no object has [CiA 301 §7.4.1], marks an empty cell).
  // Only resolve() looks into it: the profile resolves its objects once.
  std::vector<MappedObject> table_;
  std::size_t table_mask_ = 0;
  std::vector<EcatOwnedObject> owned_;
  std::span<const cia402::FaultText> faults_;
  bool fault_valid_ = false;
  std::uint16_t fault_code_ = 0;
  core::FixedString<120> fault_text_{};
  core::FixedString<200> lost_why_{};
  std::array<Pending, kMaxPending> pending_{};
};

}  // namespace drivegate::ethercat
