#include "profiles/cia402/sdo_abort.hpp"

#include <array>

namespace drivegate::cia402 {
namespace {

struct AbortText {
  std::uint32_t code;
  std::string_view text;
};

// [CiA 301 §7.2.4.3.17 "SDO abort codes"]
constexpr std::array kAborts = {
    AbortText{0x05030000, "toggle bit not alternated"},
    AbortText{0x05040000, "SDO protocol timed out"},
    AbortText{0x05040001, "client/server command specifier not valid or unknown"},
    AbortText{0x05040002, "invalid block size"},
    AbortText{0x05040003, "invalid sequence number"},
    AbortText{0x05040004, "CRC error"},
    AbortText{0x05040005, "out of memory"},
    AbortText{0x06010000, "unsupported access to an object"},
    AbortText{0x06010001, "attempt to read a write-only object"},
    AbortText{0x06010002, "attempt to write a read-only object"},
    // CoE additions [ETG.1000.6 §5.6.2.7.2]; reserved in CiA 301, so shared without conflict.
    AbortText{0x06010003, "subindex cannot be written, subindex 0 must be 0 for write access"},
    AbortText{0x06010004, "complete access not supported for objects of variable length"},
    AbortText{0x06010005, "object length exceeds the mailbox size"},
    AbortText{0x06010006, "object mapped to an RxPDO, SDO download blocked"},
    AbortText{0x06020000, "object does not exist in the object dictionary"},
    AbortText{0x06040041, "object cannot be mapped to the PDO"},
    AbortText{0x06040042, "the number and length of the objects to be mapped would exceed PDO length"},
    AbortText{0x06040043, "general parameter incompatibility"},
    AbortText{0x06040047, "general internal incompatibility in the device"},
    AbortText{0x06060000, "access failed due to a hardware error"},
    AbortText{0x06070010, "data type does not match, length of service parameter does not match"},
    AbortText{0x06070012, "data type does not match, length of service parameter too high"},
    AbortText{0x06070013, "data type does not match, length of service parameter too low"},
    AbortText{0x06090011, "sub-index does not exist"},
    AbortText{0x06090030, "invalid value for parameter (download only)"},
    AbortText{0x06090031, "value of parameter written too high (download only)"},
    AbortText{0x06090032, "value of parameter written too low (download only)"},
    AbortText{0x06090036, "maximum value is less than minimum value"},
    AbortText{0x060A0023, "resource not available: SDO connection"},
    AbortText{0x08000000, "general error"},
    AbortText{0x08000020, "data cannot be transferred or stored to the application"},
    AbortText{0x08000021, "data cannot be transferred or stored to the application because of local control"},
    AbortText{0x08000022, "data cannot be transferred or stored to the application because of the present device state"},
    AbortText{0x08000023, "object dictionary dynamic generation fails or no object dictionary is present"},
    AbortText{0x08000024, "no data available"},
};

}  // namespace

std::string_view sdo_abort_text(std::uint32_t abort_code) noexcept {
  for (const auto& a : kAborts) {
    if (a.code == abort_code) return a.text;
  }
  return "unknown abort code";
}

}  // namespace drivegate::cia402
