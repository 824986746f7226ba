// The simulated AKD PROFIdrive drive (profiles/profidrive/sim) under arbitrary scripts. Byte 0 picks
// the telegram (b % 9 of 1, 7, 9, 350, 351, 352, 353, 0, 400); then operations:
//   00h-7Fh  one cycle of (b & 0Fh) + 1 ms with the next setpoint-image-size bytes as the image
//   80h-8Fh  one cycle with a wrong-length image of (b & 0Fh) bytes (dropped and counted)
//   90h-9Fh  (b & 0Fh) + 1 cycles of 16 ms repeating the last image
//   A0h-AFh  record 47: a request of the next byte's value in bytes, then the read of the response
//   B0h-BFh  environment (b % 8): inject the next U16 as a fault, the same persistent, clear fault
//            causes, outputs valid / controller stop / lost, motor blocked on / off
// Invariants: nothing crashes; a request of 4..240 bytes is accepted and its response read back
// decodes (decode_param_response) and answers it (check_response) when it decodes itself, or is a
// one-block negative reply when it does not; every actual image decodes, has exactly one state
// pattern in ZSW1 and the fault bit exactly in the fault state.
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "profiles/profidrive/control_words.hpp"
#include "profiles/profidrive/param_access.hpp"
#include "profiles/profidrive/sim/drive_model.hpp"
#include "profiles/profidrive/telegram.hpp"

namespace {

using namespace drivegate::profidrive;
using namespace drivegate::profidrive::sim;
using namespace std::chrono_literals;

constexpr std::array<std::uint16_t, 9> kTelegrams{1, 7, 9, 350, 351, 352, 353, 0, 400};

void check_request(DriveModel& drive, std::span<const std::uint8_t> request) {
  const RecordStatus s = drive.write_parameter_record(request);
  const bool sized = request.size() >= kParamHeaderSize && request.size() <= kMaxParamRecord;
  if (s != (sized ? RecordStatus::Ok : RecordStatus::WriteLengthError)) std::abort();
  std::array<std::uint8_t, kMaxParamRecord> out{};
  const RecordRead r = drive.read_parameter_record(out);
  if (!sized) {
    if (r.status != RecordStatus::StateConflict) std::abort();
    return;
  }
  if (r.status != RecordStatus::Ok) std::abort();
  const ResponseResult resp = decode_param_response(std::span(out).first(r.size));
  if (resp.error != ParamError::None) std::abort();
  const RequestResult req = decode_param_request(request);
  if (req.error == ParamError::None) {
    if (check_response(req.request, resp.response).mismatch != ParamMismatch::None) std::abort();
  } else if (resp.response.positive() || resp.response.count != 1) {
    std::abort();
  }
}

void check_actuals(const DriveModel& drive, std::span<const std::uint8_t> image) {
  Actuals a;
  if (decode_actuals(drive.layout(), image, a) != TelegramError::None) std::abort();
  const std::uint16_t w = drive.zsw1();
  const bool s1 = (w & zsw1::kSwitchingOnInhibited) != 0;
  const bool on = (w & zsw1::kReadyToSwitchOn) != 0;
  if (s1 && on) std::abort();
  if (((w & zsw1::kFault) != 0) != (drive.state() == State::Fault)) std::abort();
  if ((w & zsw1::kOperationEnabled) != 0 && drive.state() != State::S4Operation) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0 || size > 4096) return 0;
  DriveModelConfig config;
  config.telegram = kTelegrams[data[0] % kTelegrams.size()];
  config.free_setpoint_words = 6;
  config.free_actual_words = 6;
  config.home_switch_rev = 0.5;
  DriveModel drive(config);
  std::array<std::uint8_t, 2 * kMaxTelegramWords> image{};
  std::array<std::uint8_t, 2 * kMaxTelegramWords> actual{};
  std::size_t at = 1;
  auto byte = [&]() -> std::uint8_t { return at < size ? data[at++] : 0; };
  while (at < size) {
    const std::uint8_t op = byte();
    const std::size_t out_bytes = drive.layout().setpoint_bytes();
    const auto in = std::span(actual).first(drive.layout().actual_bytes());
    if (op < 0x80) {
      for (std::size_t i = 0; i < out_bytes; ++i) image[i] = byte();
      drive.step(std::chrono::milliseconds((op & 0x0F) + 1), std::span(image).first(out_bytes), in);
      check_actuals(drive, in);
    } else if (op < 0x90) {
      drive.step(1ms, std::span(image).first(op & 0x0FU), in);
    } else if (op < 0xA0) {
      for (int i = 0; i <= (op & 0x0F); ++i) drive.step(16ms, std::span(image).first(out_bytes), in);
      check_actuals(drive, in);
    } else if (op < 0xB0) {
      const std::size_t n = std::min<std::size_t>(byte(), size - at);
      check_request(drive, std::span(data + at, n));
      at += n;
    } else {
      switch (op % 8) {
        case 0:
        case 1: {
          const auto number = static_cast<std::uint16_t>((byte() << 8) | byte());
          drive.inject_fault(number, op % 8 == 1);
          break;
        }
        case 2: drive.clear_fault_causes(); break;
        case 3: drive.set_outputs(Outputs::Valid); break;
        case 4: drive.set_outputs(Outputs::ControllerStop); break;
        case 5: drive.set_outputs(Outputs::Lost); break;
        case 6: drive.set_motor_blocked(true); break;
        default: drive.set_motor_blocked(false); break;
      }
    }
  }
  return 0;
}
