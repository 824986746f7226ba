#include "adapters/profinet/wire/rpc_status.hpp"

#include <algorithm>
#include <array>

namespace drivegate::profinet {

std::string_view error_code_text(std::uint8_t code) noexcept {
  switch (code) {
    case pnio_error_code::kOk: return "OK";
    case pnio_error_code::kPnio: return "PNIO";
    case pnio_error_code::kRtaError: return "RTA error";
    case pnio_error_code::kAlarmAck: return "AlarmAck";
    case pnio_error_code::kConnect: return "IODConnectRes";
    case pnio_error_code::kRelease: return "IODReleaseRes";
    case pnio_error_code::kControl: return "IODControlRes";
    case pnio_error_code::kRead: return "IODReadRes";
    case pnio_error_code::kWrite: return "IODWriteRes";
    default: return "unknown error code";
  }
}

std::string_view error_decode_text(std::uint8_t decode) noexcept {
  switch (decode) {
    case 0x00: return "OK";
    case pnio_error_decode::kPniorw: return "PNIORW";
    case pnio_error_decode::kPnio: return "PNIO";
    case pnio_error_decode::kManufacturer: return "manufacturer specific";
    default: return "unknown error decode";
  }
}

namespace {

// [IEC 61158-6-10 Table "Values of ErrorCode1 for ErrorDecode PNIORW"]: class in the high nibble,
// code in the low nibble.
std::string_view pniorw_text(std::uint8_t code1) noexcept {
  switch (code1) {
    case 0xA0: return "application: read error";
    case 0xA1: return "application: write error";
    case 0xA2: return "application: module failure";
    case 0xA7: return "application: busy";
    case 0xA8: return "application: version conflict";
    case 0xA9: return "application: feature not supported";
    case 0xB0: return "access: invalid index";
    case 0xB1: return "access: write length error";
    case 0xB2: return "access: invalid slot/subslot";
    case 0xB3: return "access: type conflict";
    case 0xB4: return "access: invalid area/API";
    case 0xB5: return "access: state conflict";
    case 0xB6: return "access: access denied";
    case 0xB7: return "access: invalid range";
    case 0xB8: return "access: invalid parameter";
    case 0xB9: return "access: invalid type";
    case 0xBA: return "access: backup";
    case 0xC0: return "resource: read constrain conflict";
    case 0xC1: return "resource: write constrain conflict";
    case 0xC2: return "resource: resource busy";
    case 0xC3: return "resource: resource unavailable";
    default: break;
  }
  switch (code1 >> 4) {
    case 0xA: return "application: user specific";
    case 0xB: return "access: user specific";
    case 0xC: return "resource: user specific";
    case 0xD:
    case 0xE:
    case 0xF: return "user specific";
    default: return "";
  }
}

// [IEC 61158-6-10 Table "Values of ErrorCode1 for ErrorDecode PNIO"]
std::string_view pnio_code1_text(std::uint8_t code1) noexcept {
  switch (code1) {
    case 1: return "Connect: Faulty ARBlockReq";
    case 2: return "Connect: Faulty IOCRBlockReq";
    case 3: return "Connect: Faulty ExpectedSubmoduleBlockReq";
    case 4: return "Connect: Faulty AlarmCRBlockReq";
    case 5: return "Connect: Faulty PrmServerBlockReq";
    case 6: return "Connect: Faulty MCRBlockReq";
    case 7: return "Connect: Faulty ARRPCBlockReq";
    case 8: return "Read/Write Record: Faulty Record";
    case 9: return "Connect: Faulty IRInfoBlock";
    case 10: return "Connect: Faulty SRInfoBlock";
    case 11: return "Connect: Faulty ARFSUBlock";
    case 12: return "Connect: Faulty ARVendorBlockReq";
    case 20: return "IODControl: Faulty ControlBlockConnect";
    case 21: return "IODControl: Faulty ControlBlockPlug";
    case 22: return "IOXControl: Faulty ControlBlock after a connect est.";
    case 23: return "IOXControl: Faulty ControlBlock a plug alarm";
    case 24: return "IOXControl: Faulty ControlBlockPrmBegin";
    case 25: return "IOXControl: Faulty SubmoduleListBlock";
    case 40: return "Release: Faulty ReleaseBlock";
    case 50: return "Response: Faulty ARBlockRes";
    case 51: return "Response: Faulty IOCRBlockRes";
    case 52: return "Response: Faulty AlarmCRBlockRes";
    case 53: return "Response: Faulty ModuleDiffBlock";
    case 54: return "Response: Faulty ARRPCBlockRes";
    case 60: return "AlarmAck";
    case 61: return "CMDEV";
    case 62: return "CMCTL";
    case 63: return "CTLDINA";
    case 64: return "CMRPC";
    case 65: return "ALPMI";
    case 66: return "ALPMR";
    case 67: return "LMPM";
    case 68: return "MAC";
    case 69: return "RPC";
    case 70: return "APMR";
    case 71: return "APMS";
    case 72: return "CPM";
    case 73: return "PPM";
    case 74: return "DCPUCS";
    case 75: return "DCPUCR";
    case 76: return "DCPMCS";
    case 77: return "DCPMCR";
    case 78: return "FSPM";
    case 200: return "CMSM";
    case 202: return "CMRDR";
    case 204: return "CMWRR";
    case 205: return "CMIO";
    case 206: return "CMSU";
    case 208: return "CMINA";
    case 209: return "CMPBE";
    case 210: return "CMSRL";
    case 211: return "CMDMC";
    case 253: return "RTA protocol error";
    case 255: return "user specific";
    default: return "";
  }
}

// The checking rules of the Connect blocks number the parameters in block order, the header's
// four first [IEC 61158-6-10 Tables "Values of ErrorCode2 for ErrorDecode PNIO and ErrorCode1 =
// 1/2/3/4/20/40"].
std::string_view header_param(std::uint8_t code2) noexcept {
  switch (code2) {
    case 0: return "Error in Parameter BlockType";
    case 1: return "Error in Parameter BlockLength";
    case 2: return "Error in Parameter BlockVersionHigh";
    case 3: return "Error in Parameter BlockVersionLow";
    default: return "";
  }
}

std::string_view ar_block_param(std::uint8_t code2) noexcept {
  switch (code2) {
    case 4: return "Error in Parameter ARType";
    case 5: return "Error in Parameter ARUUID";
    case 7: return "Error in Parameter CMInitiatorMACAddress";
    case 8: return "Error in Parameter CMInitiatorObjectUUID";
    case 9: return "Error in Parameter ARProperties";
    case 10: return "Error in Parameter CMInitiatorActivityTimeoutFactor";
    case 11: return "Error in Parameter InitiatorUDPRTPort";
    case 12: return "Error in Parameter StationNameLength";
    case 13: return "Error in Parameter CMInitiatorStationName";
    default: return header_param(code2);
  }
}

std::string_view iocr_block_param(std::uint8_t code2) noexcept {
  switch (code2) {
    case 4: return "Error in Parameter IOCRType";
    case 5: return "Error in Parameter IOCRReference";
    case 6: return "Error in Parameter LT";
    case 7: return "Error in Parameter IOCRProperties";
    case 8: return "Error in Parameter DataLength";
    case 9: return "Error in Parameter FrameID";
    case 10: return "Error in Parameter SendClockFactor";
    case 11: return "Error in Parameter ReductionRatio";
    case 12: return "Error in Parameter Phase";
    case 14: return "Error in Parameter FrameSendOffset";
    case 15: return "Error in Parameter WatchdogFactor";
    case 16: return "Error in Parameter DataHoldFactor";
    case 17: return "Error in Parameter IOCRTagHeader";
    case 18: return "Error in Parameter IOCRMulticastMacAddress";
    case 19: return "Error in Parameter NumberOfAPIs";
    case 20: return "Error in Parameter API";
    case 21: return "Error in Parameter NumberOfIODataObjects";
    case 22: return "Error in Parameter SlotNumber";
    case 23: return "Error in Parameter SubslotNumber";
    case 24: return "Error in Parameter IODataObjectFrameOffset";
    case 25: return "Error in Parameter NumberOfIOCS";
    case 26: return "Error in Parameter SlotNumber (IOCS)";
    case 27: return "Error in Parameter SubslotNumber (IOCS)";
    case 28: return "Error in Parameter IOCSFrameOffset";
    default: return header_param(code2);
  }
}

std::string_view expected_block_param(std::uint8_t code2) noexcept {
  switch (code2) {
    case 4: return "Error in Parameter NumberOfAPIs";
    case 5: return "Error in Parameter API";
    case 6: return "Error in Parameter SlotNumber";
    case 7: return "Error in Parameter ModuleIdentNumber";
    case 8: return "Error in Parameter ModuleProperties";
    case 9: return "Error in Parameter NumberOfSubmodules";
    case 10: return "Error in Parameter SubslotNumber";
    case 12: return "Error in Parameter SubmoduleProperties";
    case 13: return "Error in Parameter DataDescription";
    case 14: return "Error in Parameter SubmoduleDataLength";
    case 15: return "Error in Parameter LengthIOPS";
    case 16: return "Error in Parameter LengthIOCS";
    default: return header_param(code2);
  }
}

std::string_view alarm_block_param(std::uint8_t code2) noexcept {
  switch (code2) {
    case 4: return "Error in Parameter AlarmCRType";
    case 5: return "Error in Parameter LT";
    case 6: return "Error in Parameter AlarmCRProperties";
    case 7: return "Error in Parameter RTATimeoutFactor";
    case 8: return "Error in Parameter RTARetries";
    case 10: return "Error in Parameter MaxAlarmDataLength";
    case 11: return "Error in Parameter AlarmCRTagHeaderHigh";
    case 12: return "Error in Parameter AlarmCRTagHeaderLow";
    default: return header_param(code2);
  }
}

std::string_view record_param(std::uint8_t code2) noexcept {
  switch (code2) {
    case 5: return "Error in Parameter ARUUID";
    case 6: return "Error in Parameter API";
    case 7: return "Error in Parameter SlotNumber";
    case 8: return "Error in Parameter SubslotNumber";
    case 9: return "Error in Parameter Padding";
    case 10: return "Error in Parameter Index";
    case 11: return "Error in Parameter RecordDataLength";
    case 12: return "Error in Parameter TargetARUUID";
    default: return header_param(code2);
  }
}

// ControlBlockConnect (20), ControlBlockPlug (21) and ReleaseBlock (40) share their checking rules.
std::string_view control_block_param(std::uint8_t code2) noexcept {
  switch (code2) {
    case 4: return "Error in Parameter Padding";
    case 6: return "Error in Parameter SessionKey";
    case 7: return "Error in Parameter Padding/AlarmSequenceNumber";
    case 8: return "Error in Parameter ControlCommand";
    case 9: return "Error in Parameter ControlBlockProperties";
    default: return header_param(code2);
  }
}

std::string_view cmrpc_text(std::uint8_t code2) noexcept {
  switch (code2) {
    case 0: return "ArgsLength invalid";
    case 1: return "Unknown Blocks";
    case 2: return "IOCR Missing";
    case 3: return "Wrong AlarmCRBlock count";
    case 4: return "Out of AR Resources";
    case 5: return "AR UUID unknown";
    case 6: return "State conflict";
    case 7: return "Out of Provider, Consumer or Alarm Resources";
    case 8: return "Out of Memory";
    case 9: return "Pdev already owned";
    case 10: return "ARset State conflict during connection establishment";
    case 11: return "ARset Parameter conflict during connection establishment";
    case 12: return "Pdev, port(s) without interface";
    default: return "";
  }
}

}  // namespace

std::string_view error_code1_text(std::uint8_t decode, std::uint8_t code1) noexcept {
  if (decode == pnio_error_decode::kPniorw) return pniorw_text(code1);
  if (decode == pnio_error_decode::kPnio) return pnio_code1_text(code1);
  return "";
}

std::string_view error_code2_text(std::uint8_t decode, std::uint8_t code1, std::uint8_t code2) noexcept {
  if (decode != pnio_error_decode::kPnio) return "";
  switch (code1) {
    case 1: return ar_block_param(code2);
    case 2: return iocr_block_param(code2);
    case 3: return expected_block_param(code2);
    case 4: return alarm_block_param(code2);
    case 8: return record_param(code2);
    case 20:
    case 21:
    case 22:
    case 23:
    case 40: return control_block_param(code2);
    case 50:
    case 51:
    case 52:
    case 53:
    case 54: return header_param(code2);
    case 60:
      switch (code2) {
        case 0: return "Alarm Type Not Supported";
        case 1: return "Wrong Submodule State";
        default: return "";
      }
    case 61:
      switch (code2) {
        case 0: return "State Conflict";
        case 1: return "Resources";
        default: return "";
      }
    case 62:
      switch (code2) {
        case 0: return "State Conflict";
        case 1: return "Timeout";
        case 2: return "No data send";
        default: return "";
      }
    case 64: return cmrpc_text(code2);
    case 69:
      switch (code2) {
        case 1: return "CLRPC_ERR_REJECTED";
        case 2: return "CLRPC_ERR_FAULTED";
        case 3: return "CLRPC_ERR_TIMEOUT";
        case 4: return "CLRPC_ERR_IN_ARGS";
        case 5: return "CLRPC_ERR_OUT_ARGS";
        case 6: return "CLRPC_ERR_DECODE";
        case 7: return "CLRPC_ERR_PNIO_OUT_ARGS";
        case 8: return "CLRPC_ERR_PNIO_APP_TIMEOUT";
        default: return "";
      }
    case 253:
      // [IEC 61158-6-10 Table "Values of ErrorCode2 for ErrorDecode PNIO and ErrorCode1 = 253"]:
      // why an AR was aborted; the ones a controller sees most.
      switch (code2) {
        case 1: return "sequence number error (RTA_ERR_CODE_SEQ)";
        case 2: return "instance closed";
        case 3: return "AR out of memory";
        case 4: return "AR add provider or consumer failed";
        case 5: return "AR consumer DHT/WDT expired";
        case 6: return "AR CMI timeout";
        case 7: return "AR alarm-open failed";
        case 8: return "AR alarm-send.cnf(-)";
        case 9: return "AR alarm-ack-send.cnf(-)";
        case 10: return "AR alarm data too long";
        case 11: return "AR alarm.ind(err)";
        case 12: return "AR RPC client call failed";
        case 13: return "AR abort request";
        case 14: return "AR re-run aborts existing";
        case 15: return "AR release indication received";
        case 16: return "AR device deactivated";
        case 17: return "AR removed";
        case 18: return "AR protocol violation";
        case 19: return "AR name resolution error";
        case 27: return "AR link down";
        case 31: return "DCP station name changed";
        case 32: return "DCP reset to factory settings";
        case 40: return "remote application ready timeout expired";
        default: return "";
      }
    case 255: return code2 == 255 ? "User abort" : "";
    default: return "";
  }
}

namespace {

struct TextOut {
  std::span<char> out;
  std::size_t n = 0;
  void put(std::string_view s) noexcept {
    for (const char c : s) {
      if (n == out.size()) return;
      out[n++] = c;
    }
  }
  void hex2(std::uint8_t v) noexcept {
    static constexpr std::array<char, 16> kDigits{'0', '1', '2', '3', '4', '5', '6', '7',
                                                  '8', '9', 'A', 'B', 'C', 'D', 'E', 'F'};
    const std::array<char, 2> s{kDigits[v >> 4], kDigits[v & 0xF]};
    put(std::string_view(s.data(), s.size()));
  }
};

}  // namespace

std::string_view describe(const PnioStatus& s, std::span<char> out) noexcept {
  TextOut t{out};
  if (s.ok()) {
    t.put("OK");
    return {out.data(), t.n};
  }
  t.put(error_code_text(s.code));
  t.put(" ");
  t.put(error_decode_text(s.decode));
  const std::string_view c1 = error_code1_text(s.decode, s.code1);
  const std::string_view c2 = error_code2_text(s.decode, s.code1, s.code2);
  t.put(": ");
  t.put(c1.empty() ? std::string_view("unknown error") : c1);
  if (!c2.empty()) {
    t.put(": ");
    t.put(c2);
  }
  t.put(" (");
  t.hex2(s.code);
  t.put(" ");
  t.hex2(s.decode);
  t.put(" ");
  t.hex2(s.code1);
  t.put(" ");
  t.hex2(s.code2);
  t.put(")");
  return {out.data(), t.n};
}

}  // namespace drivegate::profinet
