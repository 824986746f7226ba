#include "config/profinet/device_section.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>

#include "config/scalars.hpp"
#include "config/text_util.hpp"
#include "profiles/profidrive/scaling.hpp"
#include "profiles/profidrive/telegram.hpp"

namespace drivegate::config {

namespace {

using namespace std::chrono_literals;

// The modes the PROFIdrive master drives: speed mode (pv), MDI (pp), homing (hm), program mode (tb)
// (profiles/profidrive/README.md "Commands").
constexpr core::Mode kMasterModes[] = {core::Mode::ProfileVelocity, core::Mode::ProfilePosition, core::Mode::Homing,
                                       core::Mode::TraversingBlock};

bool same(double a, double b) noexcept { return std::fabs(a - b) <= 1e-9 * std::max(std::fabs(a), std::fabs(b)); }

// The profile's units must be what the normalisation gives (profiles/profidrive/README.md "Units"):
// the master hands the drive these units as they are.
void check_units(const MapReader& pd, const DeviceProfile& p, const ProfidriveDeviceSpec& spec) {
  profidrive::AkdScaling scaling;
  scaling.single_turn_bits = spec.single_turn_bits;
  scaling.acc_full_scale_rpm_per_s = spec.acc_full_scale_rpm_per_s;
  const auto native = profidrive::native_units(scaling);
  if (!native) return;  // out of range: reported at the key
  const auto expect = [&](UnitBase base, double value, double want, const char* key, const char* unit, const char* why) {
    if (base != UnitBase::Fixed || !same(value, want))
      pd.error(key, std::string{"needs units."} + unit + " of " + format_number(want) + " per motor " +
                        (std::string_view{unit} == "position" ? "rev" : std::string_view{unit} == "velocity" ? "rev/s" : "rev/s^2") +
                        " (" + why + "), got " + (base == UnitBase::Fixed ? format_number(value) : std::string{"a unit relative to another"}));
  };
  expect(p.units.position_base, p.units.position_per_rev, native->position_per_rev, "single_turn_bits", "position",
         "2^single_turn_bits counts, PNU 1002");
  expect(p.units.velocity_base, p.units.velocity_per_rps, native->velocity_per_rps, "single_turn_bits", "velocity",
         "2^31 = 12000 rpm");
  expect(p.units.acceleration_base, p.units.acceleration_per_rps2, native->acceleration_per_rps2,
         "acc_full_scale_rpm_per_s", "acceleration", "MDI_ACC 2^16 = acc_full_scale_rpm_per_s");
}

}  // namespace

const std::vector<std::string>& known_profidrive_quirks() {
  // Where the reference drive departs from plain PROFIdrive (akd-profinet-profidrive.md).
  static const std::vector<std::string> kQuirks{
      "control_by_plc_bit10",       // §7, §8.1: STW1 without bit 10 is ignored as a whole
      "fault_ack_lands_in_s1",      // §25.17: the acknowledge edge leaves the drive in S1, not S2
      "change_reply_format_bytes",  // §5.3, §23.3: a positive change reply is ref 02 00 n + 00 00
  };
  return kQuirks;
}

void read_profidrive_device(const MapReader& root, DeviceProfile& p) {
  const MapReader pd = root.map("profidrive", Need::Required);
  pd.check_keys({"single_turn_bits", "acc_full_scale_rpm_per_s", "peak_current_a", "telegrams", "min_update_time", "quirks",
                 "vendor_id", "device_id", "idents"});
  auto& spec = p.sections.edit<ProfidriveDeviceSpec>();
  // PNU 1002: 1..31 single-turn bits, so a revolution fits a signed 32-bit position [§17.2].
  spec.single_turn_bits = static_cast<unsigned>(
      pd.integer("single_turn_bits", Need::Required, 1, 31, "a number of single-turn bits (PNU 1002, 1..31)").value_or(16));
  spec.acc_full_scale_rpm_per_s =
      pd.number("acc_full_scale_rpm_per_s", Need::Required, NumberRule::positive_up_to(1e12)).value_or(spec.acc_full_scale_rpm_per_s);
  if (const auto v = pd.number("peak_current_a", Need::Optional, NumberRule::positive_up_to(1e4))) spec.peak_current_a = *v;
  spec.min_update_time = pd.duration("min_update_time", Need::Required, 0ns, 10s).value_or(spec.min_update_time);
  if (const auto list = pd.list("telegrams", Need::Required)) {
    if (list->size() == 0) pd.error("telegrams", "must list at least one telegram");
    for (std::size_t i = 0; i < list->size(); ++i) {
      const auto t = read_integer((*list)[i], indexed(pd.field("telegrams"), i), pd.source(), 0, 65535, "a telegram number");
      if (!t) continue;
      const auto n = static_cast<std::uint16_t>(*t);
      // Telegram 0's size is set by its module [§4.3]; every other one the profile code knows.
      if (n != 0 && !profidrive::telegram_size(n))
        pd.source().error((*list)[i].Mark(), indexed(pd.field("telegrams"), i),
                          "must be a telegram the PROFIdrive profile knows (0, 1, 7, 9, 350, 351, 352, 353, 400), got " +
                              std::to_string(n));
      else if (spec.offers(n))
        pd.source().error((*list)[i].Mark(), indexed(pd.field("telegrams"), i), "telegram " + std::to_string(n) + " is listed twice");
      else
        spec.telegrams.push_back(n);
    }
  }
  if (const MapReader ids = pd.map("idents", Need::Optional); ids.present()) {
    ids.check_keys({"api", "dap_module", "dap_submodule", "telegram_module", "telegram_submodule"});
    const auto u32 = [&](const char* key, Need need, std::uint32_t fallback) {
      return static_cast<std::uint32_t>(ids.integer(key, need, 0, 0xFFFFFFFF, "a 32-bit ident number").value_or(fallback));
    };
    ProfidriveIdents id;
    id.api = u32("api", Need::Optional, id.api);
    id.dap_module = u32("dap_module", Need::Required, 0);
    id.dap_submodule = u32("dap_submodule", Need::Required, 0);
    id.telegram_module_base = u32("telegram_module", Need::Required, 0);
    id.telegram_submodule_base = u32("telegram_submodule", Need::Required, 0);
    spec.idents = id;
  }
  // The DeviceID block of a DCP Identify answer: two Unsigned16 [IEC 61158-6-10, DeviceIDValue].
  if (const auto v = pd.integer("vendor_id", Need::Optional, 0, 0xFFFF, "a PROFINET VendorID (0..0xFFFF)"))
    spec.vendor_id = static_cast<std::uint16_t>(*v);
  if (const auto v = pd.integer("device_id", Need::Optional, 0, 0xFFFF, "a PROFINET DeviceID (0..0xFFFF)"))
    spec.device_id = static_cast<std::uint16_t>(*v);
  if (spec.vendor_id.has_value() != spec.device_id.has_value())
    pd.error(spec.vendor_id ? "vendor_id" : "device_id",
             "give vendor_id and device_id together (the DCP DeviceID block has both)");
  const MapReader quirks = pd.map("quirks", Need::Optional);
  quirks.check_keys(known_profidrive_quirks());
  for (const auto& q : known_profidrive_quirks())
    if (const auto v = quirks.boolean(q, Need::Optional)) spec.quirks[q] = *v;

  for (std::size_t i = 1; i < core::kModeCount; ++i) {
    const auto mode = static_cast<core::Mode>(i);
    if (p.modes.contains(mode) && std::find(std::begin(kMasterModes), std::end(kMasterModes), mode) == std::end(kMasterModes))
      root.error("modes", "the PROFIdrive master drives pp, pv, hm and tb only, got " + std::string{core::mode_short_name(mode)});
  }
  check_units(pd, p, spec);
}

}  // namespace drivegate::config
