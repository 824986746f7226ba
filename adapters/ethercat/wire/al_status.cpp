#include "adapters/ethercat/wire/al_status.hpp"

#include <array>

namespace drivegate::ethercat {
namespace {

struct CodeText {
  std::uint16_t code;
  std::string_view text;
};

// [ETG.1000.6 §5.3.2 Table 11; ETG.1020 for 0x0004, 0x0006, 0x0007, 0x000E, 0x002E, 0x0052, 0x0070, 0x0080-0x0083].
// Sorted by code.
constexpr std::array kCodes = {
    CodeText{0x0000, "no error"},
    CodeText{0x0001, "unspecified error"},
    CodeText{0x0002, "no memory"},
    CodeText{0x0003, "invalid device setup"},
    CodeText{0x0004, "invalid revision"},
    CodeText{0x0006, "SII/EEPROM information does not match the firmware"},
    CodeText{0x0007, "firmware update failed, old firmware still running"},
    CodeText{0x000E, "license error"},
    CodeText{0x0011, "invalid requested state change"},
    CodeText{0x0012, "unknown requested state"},
    CodeText{0x0013, "bootstrap not supported"},
    CodeText{0x0014, "no valid firmware"},
    CodeText{0x0015, "invalid mailbox configuration (BOOT)"},
    CodeText{0x0016, "invalid mailbox configuration (PRE-OP)"},
    CodeText{0x0017, "invalid sync manager configuration"},
    CodeText{0x0018, "no valid inputs available"},
    CodeText{0x0019, "no valid outputs"},
    CodeText{0x001A, "synchronization error"},
    CodeText{0x001B, "sync manager watchdog"},
    CodeText{0x001C, "invalid sync manager types"},
    CodeText{0x001D, "invalid output configuration"},
    CodeText{0x001E, "invalid input configuration"},
    CodeText{0x001F, "invalid watchdog configuration"},
    CodeText{0x0020, "slave needs cold start"},
    CodeText{0x0021, "slave needs INIT"},
    CodeText{0x0022, "slave needs PRE-OP"},
    CodeText{0x0023, "slave needs SAFE-OP"},
    CodeText{0x0024, "invalid input mapping"},
    CodeText{0x0025, "invalid output mapping"},
    CodeText{0x0026, "inconsistent settings"},
    CodeText{0x0027, "free run not supported"},
    CodeText{0x0028, "sync mode not supported"},
    CodeText{0x0029, "free run needs 3-buffer mode"},
    CodeText{0x002A, "background watchdog"},
    CodeText{0x002B, "no valid inputs and outputs"},
    CodeText{0x002C, "fatal sync error"},
    CodeText{0x002D, "no sync error"},
    // Formerly "invalid input FMMU configuration" (as 002Dh was "invalid output FMMU
    // configuration"); the ETG's slave stack code has this meaning.
    CodeText{0x002E, "cycle time smaller than the minimum cycle time the slave supports"},
    CodeText{0x0030, "invalid DC SYNC configuration"},
    CodeText{0x0031, "invalid DC latch configuration"},
    CodeText{0x0032, "PLL error"},
    CodeText{0x0033, "DC sync IO error"},
    CodeText{0x0034, "DC sync timeout"},
    CodeText{0x0035, "invalid sync cycle time"},
    CodeText{0x0036, "invalid SYNC0 cycle time"},
    CodeText{0x0037, "invalid SYNC1 cycle time"},
    CodeText{0x0041, "mailbox AoE error"},
    CodeText{0x0042, "mailbox EoE error"},
    CodeText{0x0043, "mailbox CoE error"},
    CodeText{0x0044, "mailbox FoE error"},
    CodeText{0x0045, "mailbox SoE error"},
    CodeText{0x004F, "mailbox VoE error"},
    CodeText{0x0050, "EEPROM no access"},
    CodeText{0x0051, "EEPROM error"},
    CodeText{0x0052, "external hardware not ready"},
    CodeText{0x0060, "slave restarted locally"},
    CodeText{0x0061, "device identification value updated"},
    CodeText{0x0070, "detected module ident list does not match"},
    CodeText{0x0080, "supply voltage too low"},
    CodeText{0x0081, "supply voltage too high"},
    CodeText{0x0082, "temperature too low"},
    CodeText{0x0083, "temperature too high"},
    CodeText{0x00F0, "application controller available"},
};

const CodeText* find(std::uint16_t code) noexcept {
  for (const auto& c : kCodes) {
    if (c.code == code) return &c;
  }
  return nullptr;
}

}  // namespace

std::string_view al_status_text(std::uint16_t code) noexcept {
  if (const auto* c = find(code)) return c->text;
  if (code >= al_status_code::kVendorFirst) return "vendor specific";
  return "reserved";
}

bool al_status_known(std::uint16_t code) noexcept { return find(code) != nullptr; }

}  // namespace drivegate::ethercat
