#include "adapters/ethercat/bus_type.hpp"

#include <cstdio>
#include <memory>
#include <optional>

#include "adapters/ethercat/ethercat_bus.hpp"
#include "adapters/ethercat/scan.hpp"
#include "config/ethercat/bus_type.hpp"

namespace drivegate::ethercat {

namespace {

std::string micros(core::Duration d) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f us", static_cast<double>(d.count()) / 1000.0);
  return buf;
}

// The image the plan gives (SM defaults: no SII is known before the line runs). Null with `why`
// set when the plan has no image.
std::unique_ptr<ProcessImage> plan_image(const config::BusPlan& bus, std::string& why) {
  std::vector<PlannedSlave> slaves;
  try {
    slaves = planned_slaves(bus);
  } catch (const core::BusError& e) {
    why = e.what();
    return nullptr;
  }
  std::vector<ImageSlave> in;
  for (const auto& s : slaves) in.push_back(planned_image_slave(s));
  auto image = std::make_unique<ProcessImage>();
  if (!image->build(in, bus_image_options())) {
    why = "process image: " + std::string(image->text());
    return nullptr;
  }
  return image;
}

// The cyclic frame must be back well within the cycle (ProcessImage::fits: half of it, the rest
// for mailbox traffic and the application) [digest "What a master must do", step 6].
void check_image(const config::BusPlan& bus, const config::BusEntry& at) {
  std::string why;
  const auto image = plan_image(bus, why);
  if (!image) {
    if (!bus.axes.empty() || !bus.section<config::EthercatBusOptions>().io.empty())
      at.source.error(at.mark, at.path, why);
    return;
  }
  if (!image->fits(bus.cycle_time)) {
    const std::string frames =
        image->frame_count() == 1 ? "the cyclic frame (" : "the " + std::to_string(image->frame_count()) + " cyclic frames (";
    at.source.error(at.mark, at.path,
                    frames + std::to_string(image->frame_bytes()) + " bytes, " +
                        micros(image->round_trip()) + " round trip with " + std::to_string(image->slave_count()) +
                        " slaves at 100 Mbit/s) " + (image->frame_count() == 1 ? "does" : "do") +
                        " not fit in half the cycle_time of " + micros(bus.cycle_time) +
                        ": lengthen cycle_time or map fewer objects");
  }
}

void describe_image(const config::BusPlan& bus, config::DescribeRows& rows) {
  std::string why;
  const auto image = plan_image(bus, why);
  if (!image) {
    if (!bus.axes.empty()) rows.emplace_back("image", why);
    return;
  }
  std::uint32_t out = 0;
  std::uint32_t in = 0;
  for (std::size_t k = 0; k < image->slave_count(); ++k) {
    out += image->slave(k).output_bytes;
    in += image->slave(k).input_bytes;
  }
  rows.emplace_back("image", std::to_string(image->size()) + " bytes (" + std::to_string(out) + " out, " +
                                 std::to_string(in) + " in) over " + std::to_string(image->slave_count()) + " slaves, " +
                                 std::to_string(image->datagrams().size()) + " datagrams, working counter " +
                                 std::to_string(image->expected_wkc()));
  // "1 frame, 162 bytes, ..." or "2 frames (1502 + 1380 bytes), ...": the frames a cycle
  // sends, back to back (ProcessImage::kMaxFrames at most).
  std::string frames = std::to_string(image->frame_count()) + (image->frame_count() == 1 ? " frame, " : " frames (");
  for (std::size_t i = 0; i < image->frame_count(); ++i) {
    if (image->frame_count() == 1) break;
    frames += (i == 0 ? "" : " + ") + std::to_string(image->frames()[i].bytes);
  }
  frames += image->frame_count() == 1 ? std::to_string(image->frame_bytes()) + " bytes, " : " bytes), ";
  rows.emplace_back("frame", frames + micros(image->wire_time()) + " on the wire at 100 Mbit/s (round trip " +
                                 micros(image->round_trip()) + ")");
}

void describe_axis(const config::BusPlan& bus, const config::AxisPlan& axis, config::DescribeRows& rows) {
  std::string why;
  const auto image = plan_image(bus, why);
  const auto k = static_cast<std::size_t>(axis.address - 1);
  if (!image || k >= image->slave_count()) return;
  const SlaveImage& s = image->slave(k);
  char station[8];
  std::snprintf(station, sizeof station, "0x%04X", s.station);
  // Axis n of a multi-axis slave: its profile objects at + n x axis_offset [ETG.6010 §4].
  const int n = axis.section<config::EthercatAxisSpec>().slave_axis;
  char offset[32] = "";
  if (n > 0)
    std::snprintf(offset, sizeof offset, " (objects + %Xh)",
                  static_cast<unsigned>(n) * axis.device.section<config::EthercatDeviceSpec>().axis_offset);
  rows.emplace_back("slave", "position " + std::to_string(axis.address) + ", station " + station + ", axis " +
                                 std::to_string(n) + offset + ", outputs at " +
                                 std::to_string(s.output_offset) + " (" + std::to_string(s.output_bytes) +
                                 " bytes), inputs at " + std::to_string(s.input_offset) + " (" +
                                 std::to_string(s.input_bytes) + " bytes)");
}

std::unique_ptr<core::Bus> make_bus(const config::BusPlan& plan) { return make_ethercat_bus(plan); }

}  // namespace

config::BusTypeInfo bus_type() {
  config::BusTypeInfo t = config::ethercat_bus_type();
  t.check_bus.push_back(check_image);
  t.describe_bus.push_back(describe_image);
  t.describe_axis = describe_axis;
  t.make_bus = make_bus;
  t.scan = {.plan = ethercat_scan_plan, .run = run_ethercat_scan};
  return t;
}

}  // namespace drivegate::ethercat
