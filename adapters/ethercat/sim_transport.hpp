#pragma once
// `transport: sim` of an ethercat bus: the line of simulated slaves made from the plan
// (sim/line_builder.hpp, the device profiles' personas) inside the gateway's process, like the
// CANopen in-process bus. The bus sends on SimLineLink (the line's MemoryLink: the slaves answer
// inside send()); SimLinePeer gives the line the cycle's time and runs the slaves' PDI side
// (watchdogs) every cycle, before the bus reads the answers.
#include <memory>

#include "adapters/ethercat/ethercat_bus.hpp"
#include "adapters/ethercat/link/ethercat_link.hpp"
#include "adapters/ethercat/sim/line_builder.hpp"
#include "config/plan.hpp"

namespace drivegate::ethercat {

class SimLineLink final : public Link {
 public:
  explicit SimLineLink(std::shared_ptr<sim::BuiltLine> line) : line_(std::move(line)) {}
  void open() override { line_->open(); }
  void close() noexcept override { line_->link().close(); }
  [[nodiscard]] bool is_open() const noexcept override { return line_->link().is_open(); }
  SendResult send(std::span<const FrameView> frames) noexcept override { return line_->link().send(frames); }
  std::size_t receive(std::span<FrameBuffer> out) noexcept override { return line_->link().receive(out); }
  [[nodiscard]] int wait_fd() const noexcept override { return -1; }
  LinkState poll_state(core::TimePoint now) noexcept override { return line_->link().poll_state(now); }
  [[nodiscard]] LinkState state() const noexcept override { return line_->link().state(); }
  [[nodiscard]] LinkCounters counters() const noexcept override { return line_->link().counters(); }
  [[nodiscard]] std::string describe() const override { return "simulated line " + line_->bus(); }

 private:
  std::shared_ptr<sim::BuiltLine> line_;
};

class SimLinePeer final : public CyclePeer {
 public:
  explicit SimLinePeer(std::shared_ptr<sim::BuiltLine> line) : line_(std::move(line)) {}
  void step(core::TimePoint now) noexcept override {
    const auto ns = static_cast<std::uint64_t>(now.time_since_epoch().count());
    line_->line().set_time(ns);
    line_->tick(ns);
  }

 private:
  std::shared_ptr<sim::BuiltLine> line_;
};

// The bus of a `transport: sim` plan with its line. Throws core::BusError naming the position
// when a slave cannot be made.
std::unique_ptr<EthercatBus> make_simulated_ethercat_bus(const config::BusPlan& plan);

}  // namespace drivegate::ethercat
