#include "profiles/cia402/error_codes.hpp"

#include <array>

namespace drivegate::cia402 {
namespace {

// Exact codes [CiA 301 Table "Emergency error codes"; CiA 402-2 error code list].
constexpr std::array kExact = {
    FaultText{0x0000, "error reset / no error"},
    FaultText{0x1000, "generic error"},
    FaultText{0x2110, "short circuit / earth leakage (input)"},
    FaultText{0x2120, "earth leakage (input)"},
    FaultText{0x2130, "short circuit (input)"},
    FaultText{0x2211, "internal current no. 1"},
    FaultText{0x2212, "internal current no. 2"},
    FaultText{0x2213, "overcurrent in ramp function"},
    FaultText{0x2214, "overcurrent in the sequence"},
    FaultText{0x2220, "continuous overcurrent (device internal)"},
    FaultText{0x2230, "short circuit / earth leakage (device internal)"},
    FaultText{0x2240, "earth leakage (device internal)"},
    FaultText{0x2250, "short circuit (device internal)"},
    FaultText{0x2310, "continuous overcurrent (output)"},
    FaultText{0x2311, "continuous overcurrent no. 1 (output)"},
    FaultText{0x2312, "continuous overcurrent no. 2 (output)"},
    FaultText{0x2320, "short circuit / earth leakage (motor side)"},
    FaultText{0x2330, "earth leakage (motor side)"},
    FaultText{0x2340, "short circuit (motor side)"},
    FaultText{0x3110, "mains overvoltage"},
    FaultText{0x3120, "mains undervoltage"},
    FaultText{0x3130, "phase failure"},
    FaultText{0x3210, "DC link overvoltage"},
    FaultText{0x3220, "DC link undervoltage"},
    FaultText{0x3230, "DC link load error"},
    FaultText{0x3310, "output overvoltage"},
    FaultText{0x4110, "excess ambient temperature"},
    FaultText{0x4210, "excess temperature device"},
    FaultText{0x4310, "excess temperature drive (motor)"},
    FaultText{0x5112, "supply voltage +24 V low"},
    FaultText{0x5210, "measurement circuit error"},
    FaultText{0x5400, "power section error"},
    FaultText{0x5530, "data storage (EEPROM) error"},
    FaultText{0x6010, "software reset (watchdog)"},
    FaultText{0x6310, "loss of parameters"},
    FaultText{0x6320, "parameter error"},
    FaultText{0x7110, "brake chopper failure"},
    FaultText{0x7120, "motor error"},
    FaultText{0x7121, "motor blocked"},
    FaultText{0x7305, "incremental sensor 1 fault"},
    FaultText{0x7306, "incremental sensor 2 fault"},
    FaultText{0x7310, "speed sensor error"},
    FaultText{0x7320, "position sensor error"},
    FaultText{0x8110, "CAN overrun (objects lost)"},
    FaultText{0x8120, "CAN in error passive mode"},
    FaultText{0x8130, "life guard or heartbeat error"},
    FaultText{0x8140, "recovered from bus off"},
    FaultText{0x8210, "PDO not processed due to length error"},
    FaultText{0x8220, "PDO length exceeded"},
    FaultText{0x8311, "excess torque"},
    FaultText{0x8611, "following error"},
    FaultText{0x8612, "reference limit"},
    FaultText{0x9000, "external error"},
    FaultText{0xFF00, "device specific error"},
};

// Classes by leading hex digits, most specific first.
constexpr std::array kClasses2 = {
    FaultText{0x21, "current on the device input side"},
    FaultText{0x22, "current inside the device"},
    FaultText{0x23, "current on the device output side (overcurrent / short circuit)"},
    FaultText{0x31, "mains voltage"},
    FaultText{0x32, "DC link voltage"},
    FaultText{0x33, "output voltage"},
    FaultText{0x41, "ambient temperature"},
    FaultText{0x42, "device temperature"},
    FaultText{0x43, "motor temperature"},
    FaultText{0x51, "device hardware supply"},
    FaultText{0x55, "device hardware data storage"},
    FaultText{0x61, "internal software"},
    FaultText{0x62, "user software"},
    FaultText{0x63, "data set / parameters"},
    FaultText{0x71, "power module / brake"},
    FaultText{0x73, "sensor"},
    FaultText{0x81, "communication"},
    FaultText{0x82, "protocol error"},
    FaultText{0x83, "torque control monitoring"},
    FaultText{0x86, "positioning controller monitoring"},
    FaultText{0x87, "sync controller monitoring"},
    FaultText{0xFF, "device specific"},
};
constexpr std::array kClasses1 = {
    FaultText{0x1, "generic error"},
    FaultText{0x2, "current (overcurrent / short circuit)"},
    FaultText{0x3, "voltage"},
    FaultText{0x4, "temperature"},
    FaultText{0x5, "device hardware"},
    FaultText{0x6, "device software"},
    FaultText{0x7, "additional modules / sensors"},
    FaultText{0x8, "monitoring"},
    FaultText{0x9, "external error"},
    FaultText{0xF, "additional functions / device specific"},
};

template <typename Table>
const FaultText* find(const Table& table, std::uint16_t code) noexcept {
  for (const auto& e : table) {
    if (e.code == code) return &e;
  }
  return nullptr;
}

}  // namespace

std::string_view error_code_text(std::uint16_t code, std::span<const FaultText> vendor) noexcept {
  for (const auto& e : vendor) {
    if (e.code == code) return e.text;
  }
  if (const auto* e = find(kExact, code)) return e->text;
  if (const auto* e = find(kClasses2, static_cast<std::uint16_t>(code >> 8))) return e->text;
  if (const auto* e = find(kClasses1, static_cast<std::uint16_t>(code >> 12))) return e->text;
  return "unknown error code";
}

}  // namespace drivegate::cia402
