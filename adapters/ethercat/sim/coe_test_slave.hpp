#pragma once
// A CoE slave for the simulator's tests and fuzz target: 128-byte mailboxes at 1000h/1080h, 2
// output and 2 input bytes at 1100h/1180h, SDO and SDO information over a small
// SimpleObjectDictionary (device type 1000h, a u16 parameter 2000h, a 300-byte string 2001h for
// segmented transfers, a record 6040h). Header only, no test framework.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "adapters/ethercat/sim/esc_slave.hpp"
#include "adapters/ethercat/sim/object_dictionary.hpp"
#include "adapters/ethercat/wire/mailbox.hpp"
#include "adapters/ethercat/wire/registers.hpp"
#include "adapters/ethercat/wire/sii.hpp"

namespace drivegate::ethercat::sim::coe_test {

inline constexpr std::uint16_t kMbxOut = 0x1000;  // SM0, master -> slave
inline constexpr std::uint16_t kMbxIn = 0x1080;   // SM1, slave -> master
inline constexpr std::uint16_t kMbxSize = 128;
inline constexpr std::uint16_t kOut = 0x1100;
inline constexpr std::uint16_t kIn = 0x1180;

class CoeApp final : public SlaveApplication {
 public:
  CoeApp() {
    const std::array<std::uint8_t, 4> device_type{0x92, 0x01, 0x02, 0x00};  // 00020192h (CiA 402 drive)
    od.add_variable(0x1000, data_type::kUnsigned32, object_access::kReadPreOp | object_access::kReadSafeOp | object_access::kReadOp,
                    "Device type", device_type);
    const std::array<std::uint8_t, 2> u16v{0x34, 0x12};
    od.add_variable(0x2000, data_type::kUnsigned16, 0x003F, "Parameter", u16v);
    long_value.assign(300, 0);
    for (std::size_t i = 0; i < long_value.size(); ++i) long_value[i] = static_cast<std::uint8_t>('A' + i % 26);
    od.add_variable(0x2001, data_type::kOctetString, 0x003F, "Long", long_value);
    od.add_object(0x6040, object_code::kRecord, "Record");
    const std::array<std::uint8_t, 1> one{2};
    od.add_entry(OdEntrySpec{0x6040, 0, data_type::kUnsigned8, object_access::kReadPreOp, "Count", one});
    const std::array<std::uint8_t, 2> w{0, 0};
    od.add_entry(OdEntrySpec{0x6040, 1, data_type::kUnsigned16, 0x003F | object_access::kRxPdoMappable, "Word", w});
  }
  std::size_t output_size() const noexcept override { return 2; }
  std::size_t input_size() const noexcept override { return 2; }
  void exchange(std::span<const std::uint8_t>, std::span<std::uint8_t>, AlState, std::uint64_t) noexcept override {}
  ObjectDictionary* object_dictionary() noexcept override { return &od; }
  void attach(EscSlave& e) noexcept override { esc = &e; }
  void on_state_entered(AlState from, AlState to) noexcept override {
    last_from = from;
    last_to = to;
  }

  SimpleObjectDictionary od;
  EscSlave* esc = nullptr;
  AlState last_from = AlState::None;
  AlState last_to = AlState::None;
  std::vector<std::uint8_t> long_value;
};

// The slave's EEPROM image; empty when build_sii refuses the profile.
inline std::vector<std::uint8_t> coe_sii() {
  const std::array<SiiSyncManager, 4> sms{
      SiiSyncManager{kMbxOut, kMbxSize, sm_control::kMailboxOut, 0, 1, sii_sm_type::kMailboxOut},
      SiiSyncManager{kMbxIn, kMbxSize, sm_control::kMailboxIn, 0, 1, sii_sm_type::kMailboxIn},
      SiiSyncManager{kOut, 2, sm_control::kOutputs, 0, 1, sii_sm_type::kOutputs},
      SiiSyncManager{kIn, 2, sm_control::kInputs, 0, 1, sii_sm_type::kInputs},
  };
  SiiProfile p;
  p.header.identity = SiiIdentity{0x0000066F, 0x1234, 1, 7};
  p.header.standard_mailbox = SiiMailbox{kMbxOut, kMbxSize, kMbxIn, kMbxSize};
  p.header.mailbox_protocols = mailbox_protocol::kCoE;
  p.name = "CoE test slave";
  p.general.coe_details = coe_details::kSdo | coe_details::kSdoInfo;
  p.sync_managers = sms;
  std::vector<std::uint8_t> image(2048, 0);
  const auto r = build_sii(p, image);
  if (!r.ok()) return {};
  image.resize(r.size);
  return image;
}

}  // namespace drivegate::ethercat::sim::coe_test
