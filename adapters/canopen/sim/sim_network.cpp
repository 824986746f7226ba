// SimNetwork and SimPeer: see sim_network.hpp.
#include "adapters/canopen/sim/sim_network.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <utility>

#include "adapters/canopen/sim/slave_config.hpp"

namespace drivegate::canopen::sim {
namespace {

// The gateway's end of a SimPeer's wire. It holds the wire too, since CanopenBus destroys its
// peer before its transport and the wire must outlive both endpoints.
class GatewayEndpoint final : public Transport {
 public:
  GatewayEndpoint(std::shared_ptr<InprocBus> bus, std::unique_ptr<InprocEndpoint> endpoint)
      : bus_(std::move(bus)), endpoint_(std::move(endpoint)) {}

  void open() override { endpoint_->open(); }
  void close() noexcept override { endpoint_->close(); }
  [[nodiscard]] bool is_open() const noexcept override { return endpoint_->is_open(); }
  std::size_t receive(std::span<CanFrame> out, core::TimePoint now) noexcept override {
    return endpoint_->receive(out, now);
  }
  SendResult send(const CanFrame& frame, core::TimePoint now) noexcept override { return endpoint_->send(frame, now); }
  [[nodiscard]] ControllerState controller_state() const noexcept override { return endpoint_->controller_state(); }
  [[nodiscard]] TransportCounters counters() const noexcept override { return endpoint_->counters(); }
  [[nodiscard]] std::string describe() const override { return endpoint_->describe() + " (simulated drives)"; }

 private:
  std::shared_ptr<InprocBus> bus_;  // declared first: destroyed after the endpoint
  std::unique_ptr<InprocEndpoint> endpoint_;
};

}  // namespace

SimNetwork::SimNetwork(Transport& transport) : transport_(transport) {}

SlaveNode& SimNetwork::add(SlaveNodeConfig config) {
  if (find(config.node) != nullptr) {
    throw std::invalid_argument("node-ID " + std::to_string(config.node) + " is simulated twice on one bus");
  }
  nodes_.push_back(std::make_unique<SlaveNode>(std::move(config)));
  return *nodes_.back();
}

SlaveNode* SimNetwork::find(NodeId id) noexcept {
  for (auto& n : nodes_) {
    if (n->node() == id) return n.get();
  }
  return nullptr;
}

void SimNetwork::deliver(const CanFrame& frame, const SlaveNode* sender, core::TimePoint now) noexcept {
  bool taken = false;
  for (auto& n : nodes_) {
    if (n.get() != sender && n->on_frame(frame, now)) taken = true;
  }
  if (sender == nullptr && !taken) ++counters_.unclaimed;
}

void SimNetwork::step(core::TimePoint now) noexcept {
  for (;;) {
    const std::size_t got = transport_.receive(rx_, now);
    counters_.received += got;
    for (std::size_t i = 0; i < got; ++i) deliver(rx_[i], nullptr, now);
    if (got < rx_.size()) break;
  }
  for (auto& n : nodes_) {
    n->step(now, tx_);
    for (; !tx_.empty(); tx_.pop()) {
      const CanFrame& f = tx_.front();
      if (transport_.send(f, now) == SendResult::Sent) {
        ++counters_.sent;
      } else {
        ++counters_.send_failed;
      }
      deliver(f, n.get(), now);
    }
  }
}

SimPeer::SimPeer(std::shared_ptr<InprocBus> bus)
    : bus_(std::move(bus)), endpoint_(bus_->connect()), network_(*endpoint_) {
  endpoint_->open();
}

SimPeer::~SimPeer() = default;

InprocBusOptions sim_wire_options(const config::BusPlan& plan) {
  InprocBusOptions options;
  options.tx_queue_capacity = std::max<std::size_t>(options.tx_queue_capacity, 8 * plan.axes.size() + 64);
  return options;
}

SimPeer::Wiring SimPeer::wire(const config::BusPlan& plan) {
  auto bus = std::make_shared<InprocBus>(plan.section<config::CanopenBusOptions>().bitrate, sim_wire_options(plan));
  auto endpoint = bus->connect();
  const InprocEndpoint* gateway_end = endpoint.get();
  auto gateway = std::make_unique<GatewayEndpoint>(bus, std::move(endpoint));
  std::unique_ptr<SimPeer> peer(new SimPeer(std::move(bus)));
  peer->gateway_end_ = gateway_end;
  for (const auto& axis : plan.axes) peer->network_.add(slave_config_for(axis));
  return {std::move(gateway), std::move(peer)};
}

void SimPeer::step(core::TimePoint now) noexcept {
  // Deliver what the gateway sent last cycle, let the drives answer, and put their frames on the
  // wire (at bit rate 0 they arrive at once; otherwise as the medium carries them).
  bus_->advance(now);
  network_.step(now);
  bus_->advance(now);
}

}  // namespace drivegate::canopen::sim
