// The RPC and block codecs allocate nothing (DESIGN.md §3: the bus thread composes and parses
// these): a Connect request composed and decoded block by block, a Connect response walked with
// its ModuleDiff report, a record write/read and a control call, a status described, all with the
// allocation counter armed (tests/support/alloc_counter.hpp).
#include <gtest/gtest.h>

#include <array>

#include "adapters/profinet/wire/rpc_calls.hpp"
#include "adapters/profinet/wire/rpc_connect.hpp"
#include "tests/profinet_rpc/scenario.hpp"
#include "tests/support/alloc_counter.hpp"

namespace drivegate::profinet {
namespace {

TEST(PnNoAlloc, ConnectToRelease) {
  const test::Scenario s;
  const ConnectRequest c = s.connect();
  std::array<std::uint8_t, 1464> buf{};
  std::array<std::uint8_t, 1464> res{};
  std::array<char, 512> text{};
  const std::array<IocrBlockRes, 2> iocrs{{{iocr_type::kInput, 1, 0xC001}, {iocr_type::kOutput, 2, 0xC002}}};
  const std::array<ModuleDiffSubmodule, 1> subs{{{1, 2, 0x9000}}};
  const std::array<ModuleDiffModule, 1> mods{{{1, 0x102, ModuleState::WrongModule, subs}}};
  const std::array<ModuleDiffApi, 1> apis{{{test::kProfidriveApi, mods}}};
  const std::array<std::uint8_t, 14> pnu930{0x05, 0x02, 0x00, 0x01, 0x10, 0x01, 0x03, 0xA2, 0x00, 0x00, 0x42, 0x01, 0x00, 0x02};
  std::size_t entries = 0;
  std::size_t blocks = 0;
  std::size_t report = 0;
  std::size_t data = 0;

  const drivegate::test::AllocationScope scope;
  for (std::uint32_t round = 0; round < 50; ++round) {
    const RpcHeader req = test::device_call(Opnum::Connect, round, round % 2 == 0 ? ByteOrder::Little : ByteOrder::Big);
    const std::size_t n = encode_connect_request(req, test::kArgsMaximum, c, buf);
    const PnioRequestView rv = decode_pnio_request(std::span(buf).first(n));
    BlockWalker w(rv.ndr.blocks);
    BlockView b;
    while (w.next(b)) {
      ++blocks;
      if (b.header.type == block_type::kIocrBlockReq) {
        IocrEntryReader r(decode_iocr_block_req(b.block));
        IocrEntry e;
        while (r.next(e)) ++entries;
      } else if (b.header.type == block_type::kExpectedSubmoduleBlockReq) {
        ExpectedSubmoduleReader r(decode_expected_submodule_block(b.block));
        ExpectedEntry e;
        while (r.next(e)) ++entries;
      } else if (b.header.type == block_type::kArBlockReq) {
        entries += decode_ar_block_req(b.block).block.station_name.size();
      } else {
        entries += decode_alarm_cr_block_req(b.block).block.rta_retries;
      }
    }
    ConnectResponse cr;
    cr.ar = {ar_type::kIocarSingle, test::kArUuid, 1, test::kDeviceMac, kEtherTypePnio};
    cr.iocrs = iocrs;
    cr.module_diff = apis;
    const std::size_t m = encode_connect_response(response_header_for(req, 1), {}, test::kArgsMaximum, cr, res);
    const ConnectResponseView cv = decode_connect_response(std::span(res).first(m));
    report += module_diff_report(cv.module_diff, s.expected, text).size();

    RecordReqHeader wr;
    wr.type = block_type::kWriteReqHeader;
    wr.ar_uuid = test::kArUuid;
    wr.slot = 1;
    wr.subslot = 1;
    wr.index = record_index::kAkdParameterAccess;
    const std::size_t k = encode_write_request(test::device_call(Opnum::Write, round), test::kArgsMaximum, wr, pnu930, buf);
    data += decode_record_request(decode_pnio_request(std::span(buf).first(k)).ndr.blocks).data.size();
    const ControlBlock prm{block_type::kPrmEndReq, test::kArUuid, 1, 0, control_command::kPrmEnd, 0};
    const std::size_t q = encode_control_request(test::device_call(Opnum::Control, round), test::kArgsMaximum, prm, buf);
    data += decode_control_block(decode_pnio_request(std::span(buf).first(q)).ndr.blocks).block.command;
    report += describe({0xDB, 0x81, 0x01, 0x04}, text).size();
  }
  EXPECT_EQ(scope.count(), 0U);
  EXPECT_EQ(blocks, 50U * 6);
  EXPECT_EQ(entries, 50U * (9 + 3 + 3 + 3 + 1 + 1));  // name, IOCR entries in and out, retries, 2 slots
  EXPECT_EQ(data, 50U * (14 + 1));
  EXPECT_GT(report, 0U);
}

}  // namespace
}  // namespace drivegate::profinet
