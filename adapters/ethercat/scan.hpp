#pragma once
// The EtherCAT bus scan (`drivegated --scan ethercat:IFACE`, DESIGN.md §7, issue 9 "Bus scan"):
// which slaves are on the line, what they are, and which device profile runs them. Needs no
// configuration.
//
//   1. LineBoot with no configured slave: every position accepts any identity (accept_identities
//      with `any`), so the line is counted, reset, addressed (1001h, 1002h, ...), every SII read and
//      every slave taken to PRE-OP (its mailbox SMs from the SII) [dunker-ethercat-coe.md "What an
//      EtherCAT master must do", steps 1-2; ETG.1000.6 §5.3, §5.4].
//   2. Per slave FPRD 0008h, the ESC features: bit 2 distributed clocks [ETG.1000.4 Table 31].
//   3. Per CoE slave (SII mailbox protocols 001Ch bit 2 and a standard mailbox), one request after
//      the other over a CoeSdoClient: 1000h, 1018h:01..04, 1C12h:00 and 1C13h:00, each assigned
//      PDO (1C12h:n, 1C13h:n) and its mapping (PDO:00, PDO:n) [ETG.1000.6 §5.6.7.4 PDO
//      assignment and mapping]. Without 1C12h/1C13h the PDOs are the SII's.
//   4. Per CoE slave whose SII general category says SDO Information (CoE details bit 1,
//      ETG.1000.6 Table 21): Get OD List of all objects [ETG.1000.6 §5.6.3.3], its fragments
//      joined; with `objects=1` (EthercatScanSettings::object_names) each object's name by Get
//      Object Description [§5.6.3.5]. The table shows the count by area (communication,
//      manufacturer, profile), with the option every object with its name.
//   5. The line stays in PRE-OP (a slave whose PRE-OP failed stays where it stopped, INIT mostly).
//
// The device profile of a slave: one of the profile's `ethercat.identities` is its SII identity
// (revision where the profile names one), else a profile without identities (generic-cia402) when
// its 1000h names CiA 402 (profile number 0192h in the low word; digest "generic profile").
// Slaves without CoE are I/O slaves: an `io:` entry of the skeleton with their SII identity and
// process data sizes (SyncM categories, as the bus takes them). CoE slaves without a profile are
// comments, or `io:` entries where the skeleton needs their position (every position up to the
// last configured one must be configured).
//
// EthercatScan is sans-I/O (frames in through Transactions, time as a parameter); scan_link()
// drives it on a Link with a ScanClock (real time on a RawSocketLink, virtual time on the
// simulator's line in tests).
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "adapters/ethercat/link/ethercat_link.hpp"
#include "adapters/ethercat/master/coe_sdo_client.hpp"
#include "adapters/ethercat/master/line_boot.hpp"
#include "adapters/ethercat/master/transactions.hpp"
#include "config/bus_types.hpp"
#include "config/plan.hpp"
#include "core/clock.hpp"
#include "core/scan.hpp"

namespace drivegate::ethercat {

struct EthercatScanSettings {
  core::Duration frame_timeout = std::chrono::milliseconds(100);  // a frame not back by then is lost
  core::Duration sdo_timeout = std::chrono::seconds(1);           // one CoE request
  core::Duration budget = std::chrono::seconds(30);               // the whole scan at most
  bool object_names = false;       // objects=1: every object's name (one request each)
  std::size_t max_objects = 2048;  // an OD list longer than this is not read (05040005h)
};

// An object of the slave's dictionary as SDO Information lists it.
struct ScannedObject {
  std::uint16_t index = 0;
  std::uint8_t object_code = 0;  // 7 variable, 8 array, 9 record; 0 when not described
  std::string name;              // "" when not read
};

struct ScannedPdoEntry {
  std::uint16_t index = 0;
  std::uint8_t subindex = 0;
  std::uint8_t bits = 0;
};
struct ScannedPdo {
  std::uint16_t index = 0;
  std::vector<ScannedPdoEntry> entries;
  [[nodiscard]] std::uint32_t bits() const noexcept;
};

// What the scan learned of one slave.
struct ScannedSlave {
  std::uint16_t position = 0;  // 1 = next to the master
  std::uint16_t station = 0;
  SiiIdentity identity{};      // from the SII
  std::string name;            // the SII general category's name, "" without one
  std::uint16_t mailbox_protocols = 0;  // SII word 001Ch
  std::uint8_t coe_details = 0;         // SII general category
  bool sii_ok = false;
  std::optional<std::uint16_t> esc_features;  // 0008h
  AlState state = AlState::Init;              // where the scan left it
  std::string boot_text;                      // LineBoot's sentence when it stopped early
  bool coe = false;                           // read over CoE (a mailbox and CoE in the SII)
  std::optional<std::uint32_t> device_type;   // 1000h
  std::array<std::optional<std::uint32_t>, 4> identity_object{};  // 1018h:01..04
  std::string pdo_source;                     // "1C12h/1C13h", "SII", "" (none)
  std::vector<ScannedPdo> rxpdos;             // outputs (SM2)
  std::vector<ScannedPdo> txpdos;             // inputs (SM3)
  std::uint32_t sm_output_bytes = 0;          // SII SyncM categories (type outputs / inputs)
  std::uint32_t sm_input_bytes = 0;
  bool sdo_info = false;                      // the SII says SDO Information (CoE details bit 1)
  bool objects_read = false;                  // its OD list came (objects holds it, maybe 0)
  std::vector<ScannedObject> objects;         // by the list's order
  std::vector<std::string> notes;

  [[nodiscard]] bool dc() const noexcept { return esc_features && (*esc_features & 0x0004U) != 0; }
};

class EthercatScan final : public DatagramOwner {
 public:
  explicit EthercatScan(EthercatScanSettings settings);
  ~EthercatScan();
  EthercatScan(const EthercatScan&) = delete;
  EthercatScan& operator=(const EthercatScan&) = delete;

  void start(core::TimePoint now);
  void poll(core::TimePoint now, Transactions& tx);
  void on_result(std::uint32_t tag, const DatagramAnswer& answer) noexcept override;
  [[nodiscard]] bool done() const noexcept { return phase_ == Phase::Done; }

  // After done(): the slaves by position, and what stopped the line (empty when it ran).
  [[nodiscard]] const std::vector<ScannedSlave>& slaves() const noexcept { return slaves_; }
  [[nodiscard]] const std::string& line_text() const noexcept { return line_text_; }

 private:
  enum class Phase : std::uint8_t { Boot, Registers, Coe, Done };
  enum class Read : std::uint8_t { DeviceType, Identity, AssignCount, AssignEntry, MapCount, MapEntry, OdList,
                                    ObjectName };
  struct Request {
    Read what = Read::DeviceType;
    std::uint16_t index = 0;
    std::uint8_t subindex = 0;
    bool tx = false;        // 1C13h / TxPDO
    std::size_t pdo = 0;    // MapCount/MapEntry: which PDO of the direction; ObjectName: which object
  };
  struct CoeRun {
    std::unique_ptr<CoeSdoClient> client;
    std::vector<Request> todo;  // front first
    std::size_t next = 0;
    CoeSdoId running = 0;
    Request current{};
    bool assign_rx_ok = false, assign_tx_ok = false;
    bool finished = false;
    std::vector<std::uint16_t> list;  // Get OD List target (max_objects)
    std::array<char, 128> name{};     // Get Object Description target
    std::size_t names_failed = 0;
    std::uint32_t first_name_abort = 0;
  };

  void boot_finished();
  void coe_answer(std::size_t k, const Request& r, const CoeSdoResult& result);
  CoeSdoId coe_request(CoeRun& run);
  void finish(core::TimePoint now);

  EthercatScanSettings settings_;
  std::array<ExpectedSlave, LineBoot::kMaxSlaves> expected_{};
  std::unique_ptr<LineBoot> boot_;
  Phase phase_ = Phase::Boot;
  core::TimePoint deadline_{};
  std::size_t registers_left_ = 0;
  bool registers_queued_ = false;
  std::vector<CoeRun> coe_;
  std::vector<ScannedSlave> slaves_;
  std::string line_text_;
};

// What runs the scan's time: now() and a wait until `until` (or until a frame may have arrived).
class ScanClock {
 public:
  virtual ~ScanClock() = default;
  virtual core::TimePoint now() = 0;
  virtual void wait(core::TimePoint until, const Link& link) = 0;
};

// The scan on an open link. Throws core::ScanError when the scan's budget runs out.
std::vector<ScannedSlave> scan_line(Link& link, const EthercatScanSettings& settings, ScanClock& clock,
                                    std::string& line_text);

// The device profiles with an ethercat section in the directories, in name order; broken ones are
// left out with a note in `notes`.
std::vector<config::DeviceProfile> ethercat_scan_profiles(const std::vector<std::filesystem::path>& dirs,
                                                          const config::BusTypeRegistry& types,
                                                          std::vector<std::string>& notes);

// The table's rows and the skeleton's parts of what the scan found on `interface`, profiles matched.
core::ScanResult ethercat_scan_result(const std::vector<ScannedSlave>& slaves, const std::string& line_text,
                                      const std::string& interface, const std::vector<config::DeviceProfile>& profiles);

// `ethercat:IFACE[?key=value&...]` checked by the configuration's rules for a raw ethercat bus
// (interface, sdo_timeout, transition_timeout), and the scan's own `objects` (0/1: list every
// object's name). Throws core::ScanError naming the option.
config::BusPlan ethercat_scan_plan(const core::ScanRequest& request, const config::BusTypeRegistry& types);
// `objects=1` in the request (checked by ethercat_scan_plan).
bool ethercat_scan_object_names(const core::ScanRequest& request);

// The scan on a RawSocketLink on the plan's interface in real time. Throws core::ScanError when
// the interface does not open.
core::ScanResult run_ethercat_scan(const config::BusPlan& plan, const core::ScanRequest& request,
                                   const config::BusTypeRegistry& types);

}  // namespace drivegate::ethercat
