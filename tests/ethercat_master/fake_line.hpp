#pragma once
// A scripted fake EtherCAT line for the master engine tests: each fake ESC is a 64 KiB register
// and RAM space that answers datagrams as ETG.1000.4 §5.4 says (auto-increment: addressed where the
// ADP is 0 on arrival, every slave increments it; configured: station address 0010h equal to ADP;
// broadcast: every slave, reads OR-ed; WKC +1 per read or write executed), plus the few register
// behaviours the engines rely on: AL control/status/status code [ETG.1000.6 §5.3.2], the SII
// EEPROM interface [ETG.1000.4 Table 48] and the SM0/SM1 mailbox (write to SM0 hands the request
// to a script; SM1 reads are empty (WKC 0) until the script replied; mailbox full bit 080Dh.3;
// repeat bit 080Eh.1 / acknowledge 080Fh.1) [ETG.1000.4 §6 SyncManager]. It is not the simulator.
#include <cstdint>
#include <functional>
#include <map>
#include <span>
#include <vector>

#include "adapters/ethercat/wire/al_status.hpp"
#include "adapters/ethercat/wire/frame.hpp"
#include "adapters/ethercat/wire/registers.hpp"
#include "core/bytes.hpp"

namespace drivegate::ethercat {
using core::get_u16;
using core::get_u32;
using core::put_u16;
}  // namespace drivegate::ethercat

namespace drivegate::ethercat::test {

struct FakeEsc {
  std::vector<std::uint8_t> mem = std::vector<std::uint8_t>(0x10000, 0);
  std::vector<std::uint8_t> sii;      // EEPROM image
  bool sii_eight_bytes = false;       // 0502h bit 6
  int sii_busy_reads = 0;             // reads of 0502h that report busy after each command
  int sii_nacks = 0;                  // read commands answered with the "no acknowledge" bit 13
  int busy_left = 0;
  std::map<std::uint8_t, std::uint16_t> refuse;  // requested state -> AL status code
  bool never_reach = false;           // accept requests but stay in the current state
  int al_delay_reads = 0;             // AL status reads before a requested state is reached
  int delay_left = 0;
  std::uint8_t pending_state = 0;
  std::vector<std::uint16_t> al_control_writes;
  // Every write: address, and its first two bytes little-endian (one byte: that byte).
  std::vector<std::pair<std::uint16_t, std::uint16_t>> writes;
  std::uint8_t state_when_addressed = 0;  // AL state when the station address (0010h) was written
  // Mailbox
  std::function<void(FakeEsc&, std::span<const std::uint8_t>)> on_mailbox;  // request written to SM0
  std::vector<std::vector<std::uint8_t>> requests;
  std::vector<std::uint8_t> last_reply;
  bool sm1_full = false;
  int sm1_reads = 0;

  FakeEsc() { put_u16(mem, reg::kAlStatus, 1); }

  std::uint16_t station() const { return get_u16(mem, reg::kStationAddress); }
  std::uint8_t al_state() const { return static_cast<std::uint8_t>(mem[reg::kAlStatus] & 0x0F); }
  SmEntry sm(unsigned n) const { return *decode_sm(std::span<const std::uint8_t>(mem).subspan(reg::sm(n), 8)); }

  void reply(std::span<const std::uint8_t> mailbox) {
    const SmEntry sm1 = sm(1);
    last_reply.assign(sm1.length, 0);
    std::copy_n(mailbox.begin(), std::min<std::size_t>(mailbox.size(), sm1.length), last_reply.begin());
    place_reply();
  }
  void place_reply() {
    const SmEntry sm1 = sm(1);
    std::copy(last_reply.begin(), last_reply.end(), mem.begin() + sm1.physical_start);
    sm1_full = true;
  }

  // Returns true when the slave executed the read (WKC +1).
  bool read(std::uint16_t ado, std::span<std::uint8_t> out) {
    const std::size_t end = static_cast<std::size_t>(ado) + out.size();
    const SmEntry sm1 = sm(1);
    const bool in_sm1 = sm1.enabled() && ado >= sm1.physical_start && ado < sm1.physical_start + sm1.length;
    if (in_sm1 && !sm1_full) return false;  // empty mailbox: no WKC [ETG.1000.4 §6 SyncManager, 1-buffer]
    if (ado <= reg::kSiiControl && end > reg::kSiiControl) {
      std::uint16_t ctl = get_u16(mem, reg::kSiiControl);
      ctl = static_cast<std::uint16_t>((ctl & ~sii_control::kBusy & ~sii_control::kRead8Bytes) |
                                       (busy_left > 0 ? sii_control::kBusy : 0) |
                                       (sii_eight_bytes ? sii_control::kRead8Bytes : 0));
      put_u16(mem, reg::kSiiControl, ctl);
      if (busy_left > 0) --busy_left;
    }
    if (ado <= reg::kAlStatus && end > reg::kAlStatus && pending_state != 0) {
      if (delay_left > 0) {
        --delay_left;
      } else {
        put_u16(mem, reg::kAlStatus, pending_state);
        pending_state = 0;
      }
    }
    // 080Dh (SM1 status): mailbox full bit.
    mem[reg::sm_status(1)] = static_cast<std::uint8_t>(sm1_full ? sm_status::kMailboxFull : 0);
    std::copy_n(mem.begin() + ado, out.size(), out.begin());
    // Reading the last byte of SM1 frees the mailbox.
    if (in_sm1 && end >= static_cast<std::size_t>(sm1.physical_start + sm1.length)) {
      sm1_full = false;
      ++sm1_reads;
    }
    return true;
  }

  bool write(std::uint16_t ado, std::span<const std::uint8_t> in) {
    const std::size_t end = static_cast<std::size_t>(ado) + in.size();
    const SmEntry sm0 = sm(0);
    const bool in_sm0 = sm0.enabled() && ado >= sm0.physical_start && ado < sm0.physical_start + sm0.length;
    const std::uint8_t old_activate1 = mem[reg::sm_activation(1)];
    writes.emplace_back(ado, in.size() >= 2 ? get_u16(in, 0) : (in.empty() ? std::uint16_t{0} : in[0]));
    if (ado == reg::kStationAddress) state_when_addressed = al_state();
    std::copy(in.begin(), in.end(), mem.begin() + ado);
    if (ado <= reg::kAlControl && end > reg::kAlControl) al_control(get_u16(mem, reg::kAlControl));
    if (ado <= reg::kSiiControl && end > reg::kSiiControl) sii_command();
    if (ado <= reg::sm_activation(1) && end > reg::sm_activation(1)) {
      const std::uint8_t now = mem[reg::sm_activation(1)];
      if (((now ^ old_activate1) & sm_activate::kRepeat) != 0) {  // repeat request toggled
        if (!last_reply.empty()) place_reply();
        const std::uint8_t ack = (now & sm_activate::kRepeat) != 0 ? sm_pdi_control::kRepeatAck : std::uint8_t{0};
        mem[reg::sm_pdi_control(1)] =
            static_cast<std::uint8_t>((mem[reg::sm_pdi_control(1)] & ~sm_pdi_control::kRepeatAck) | ack);
      }
    }
    if (in_sm0 && end >= static_cast<std::size_t>(sm0.physical_start + sm0.length)) {
      std::vector<std::uint8_t> req(mem.begin() + sm0.physical_start, mem.begin() + sm0.physical_start + sm0.length);
      requests.push_back(req);
      if (on_mailbox) on_mailbox(*this, req);
    }
    return true;
  }

  void al_control(std::uint16_t v) {
    al_control_writes.push_back(v);
    const auto requested = static_cast<std::uint8_t>(v & 0x0F);
    const bool ack = (v & kAlErrorBit) != 0;
    std::uint16_t status = get_u16(mem, reg::kAlStatus);
    if ((status & kAlErrorBit) != 0) {
      if (!ack) return;  // an error must be acknowledged first
      status = static_cast<std::uint16_t>(status & ~kAlErrorBit);
      put_u16(mem, reg::kAlStatusCode, 0);
    }
    const auto current = static_cast<std::uint8_t>(status & 0x0F);
    if (requested == current || never_reach) {
      put_u16(mem, reg::kAlStatus, status);
      return;
    }
    std::uint16_t code = 0;
    if (auto it = refuse.find(requested); it != refuse.end()) code = it->second;
    // PRE-OP needs SM0/SM1 as the SII describes them (0016h invalid mailbox configuration).
    if (requested == 2 && sii.size() >= 0x38) {
      const std::uint16_t rx = get_u16(sii, 0x30);
      const std::uint16_t rx_size = get_u16(sii, 0x32);
      if (rx_size != 0 && (sm(0).physical_start != rx || sm(0).length != rx_size || !sm(0).enabled() ||
                           !sm(1).enabled())) {
        code = al_status_code::kInvalidMailboxConfigPreOp;
      }
    }
    if (code != 0) {
      put_u16(mem, reg::kAlStatus, static_cast<std::uint16_t>(current | kAlErrorBit));
      put_u16(mem, reg::kAlStatusCode, code);
      return;
    }
    pending_state = requested;
    delay_left = al_delay_reads;
  }

  void sii_command() {
    const std::uint16_t ctl = get_u16(mem, reg::kSiiControl);
    if ((ctl & sii_control::kCommandMask) != sii_control::kCommandRead) return;
    if (sii_nacks > 0) {  // the EEPROM did not acknowledge: error bit 13, no data [ETG.1000.4 Table 48]
      --sii_nacks;
      put_u16(mem, reg::kSiiControl,
              static_cast<std::uint16_t>((ctl & ~sii_control::kCommandMask) | sii_control::kCommandError));
      busy_left = sii_busy_reads;
      return;
    }
    const std::uint32_t word = get_u32(mem, reg::kSiiAddress);
    const std::size_t n = sii_eight_bytes ? 8 : 4;
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t at = 2 * static_cast<std::size_t>(word) + i;
      mem[reg::kSiiData + i] = at < sii.size() ? sii[at] : 0xFF;
    }
    put_u16(mem, reg::kSiiControl, static_cast<std::uint16_t>(ctl & ~sii_control::kCommandMask));
    busy_left = sii_busy_reads;
  }
};

struct FakeLine {
  std::vector<FakeEsc> slaves;

  // Processes a frame in place as it passes every slave.
  void process(std::span<std::uint8_t> frame) {
    FrameParser p(frame);
    Datagram d;
    std::vector<Datagram> all;
    while (p.next(d)) all.push_back(d);
    for (const Datagram& g : all) {
      std::span<std::uint8_t> data = frame.subspan(g.data_offset, g.header.length);
      std::uint16_t adp = g.header.adp();
      const std::uint16_t ado = g.header.ado();
      std::uint16_t wkc = g.wkc;
      for (FakeEsc& s : slaves) {
        const Command c = g.header.command;
        bool addressed = false;
        switch (addressing_of(c)) {
          case Addressing::AutoIncrement: addressed = adp == 0; break;
          case Addressing::Configured: addressed = adp == s.station(); break;
          case Addressing::Broadcast: addressed = true; break;
          default: break;
        }
        if (addressed) {
          if (c == Command::BRD) {
            std::vector<std::uint8_t> tmp(data.size());
            if (s.read(ado, tmp)) {
              for (std::size_t i = 0; i < tmp.size(); ++i) data[i] = static_cast<std::uint8_t>(data[i] | tmp[i]);
              ++wkc;
            }
          } else if (access_of(c) == Access::Read) {
            if (s.read(ado, data)) ++wkc;
          } else if (access_of(c) == Access::Write) {
            if (s.write(ado, data)) ++wkc;
          }
        }
        if (addressing_of(c) == Addressing::AutoIncrement || addressing_of(c) == Addressing::Broadcast) ++adp;
      }
      put_u16(frame, g.header_offset + 2, adp);
      put_u16(frame, g.wkc_offset, wkc);
    }
  }
};

}  // namespace drivegate::ethercat::test
