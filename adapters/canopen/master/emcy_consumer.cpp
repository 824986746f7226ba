// EMCY consumer: see emcy_consumer.hpp. The node table and the report ring are sized in the
// constructor; on_frame formats into fixed buffers only.
#include "adapters/canopen/master/emcy_consumer.hpp"

#include <algorithm>
#include <cstdio>
#include <optional>
#include <stdexcept>
#include <string>

namespace drivegate::canopen {

EmcyConsumer::EmcyConsumer(std::span<const EmcyNodeConfig> nodes) : reports_(kReportCapacity) {
  nodes_.reserve(nodes.size());
  for (const auto& cfg : nodes) {
    if (!valid_node_id(cfg.node)) {
      throw std::invalid_argument("EMCY consumer: node-ID " + std::to_string(cfg.node) + " is outside 1..127");
    }
    if (index_[cfg.node] != 0) {
      throw std::invalid_argument("EMCY consumer: node-ID " + std::to_string(cfg.node) + " is registered twice");
    }
    for (const auto& f : cfg.fields) {
      if (f.byte < 3 || f.byte > 7) {
        throw std::invalid_argument("EMCY consumer: field '" + std::string(f.name) + "' of node " +
                                    std::to_string(cfg.node) + " is in byte " + std::to_string(f.byte) +
                                    "; vendor bytes are 3..7");
      }
    }
    nodes_.push_back(Node{cfg, {}, false});
    index_[cfg.node] = static_cast<std::uint8_t>(nodes_.size());
  }
}

void EmcyConsumer::describe(const Node& n, const Emcy& e, bool cleared, EmcyReport& out) const noexcept {
  // snprintf into one buffer, then a single assign: FixedString cuts visibly if it is too long.
  std::array<char, 2 * decltype(out.text)::capacity()> buf{};
  std::size_t at = 0;
  const auto append = [&](int written) {
    if (written > 0) at = std::min(buf.size() - 1, at + static_cast<std::size_t>(written));
  };
  if (e.code == 0 && !cleared) {
    // AKD part 1 §9.2 transition 2 / quirk 4: "no error" would be the wrong thing to tell a person.
    append(std::snprintf(buf.data(), buf.size(), "0x0000 error state update, errors pending (register 0x%02X)",
                         static_cast<unsigned>(e.error_register)));
  } else {
    const auto text = cia402::error_code_text(e.code, n.config.texts);
    append(std::snprintf(buf.data(), buf.size(), "0x%04X %.*s", static_cast<unsigned>(e.code),
                         static_cast<int>(text.size()), text.data()));
  }
  const char* sep = " (";
  for (const auto& f : n.config.fields) {
    append(std::snprintf(buf.data() + at, buf.size() - at, "%s%.*s %u", sep, static_cast<int>(f.name.size()),
                         f.name.data(), static_cast<unsigned>(e.vendor[f.byte - 3U])));
    sep = ", ";
  }
  if (!n.config.fields.empty()) append(std::snprintf(buf.data() + at, buf.size() - at, ")"));
  out.text.assign(std::string_view(buf.data(), at));
}

bool EmcyConsumer::on_frame(const CanFrame& frame, core::TimePoint now) noexcept {
  if (frame.extended) return false;
  const auto split = split_cob_id(frame.id);
  if (split.function != Function::Emcy) return false;  // SYNC 080h has node 0: not ours
  ++counters_.received;
  if (split.node > kMaxNodeId || index_[split.node] == 0) {
    ++counters_.unexpected;
    return true;
  }
  const auto decoded = frame.remote || !frame.valid() ? std::nullopt : decode_emcy(frame.payload());
  if (!decoded) {
    ++counters_.malformed;
    return true;
  }
  Node& n = nodes_[index_[split.node] - 1U];
  const bool cleared = decoded->code == 0 && (decoded->error_register == 0 || !n.config.zero_needs_clear_register);

  EmcyReport report;
  report.node = split.node;
  report.emcy = *decoded;
  report.cleared = cleared;
  report.time = now;
  describe(n, *decoded, cleared, report);

  if (cleared) {
    n.has_active = false;
  } else if (decoded->code != 0 || !n.has_active) {
    // A new fault replaces the active one; an update with errors pending keeps it.
    n.active = report;
    n.has_active = true;
  }

  if (report_count_ == kReportCapacity) {
    ++counters_.reports_dropped;
  } else {
    reports_[(report_head_ + report_count_) % kReportCapacity] = report;
    ++report_count_;
  }
  return true;
}

bool EmcyConsumer::next_report(EmcyReport& out) noexcept {
  if (report_count_ == 0) return false;
  out = reports_[report_head_];
  report_head_ = (report_head_ + 1) % kReportCapacity;
  --report_count_;
  return true;
}

const EmcyReport* EmcyConsumer::active(NodeId node) const noexcept {
  if (node > kMaxNodeId || index_[node] == 0) return nullptr;
  const Node& n = nodes_[index_[node] - 1U];
  return n.has_active ? &n.active : nullptr;
}

void EmcyConsumer::reset(NodeId node) noexcept {
  if (node <= kMaxNodeId && index_[node] != 0) nodes_[index_[node] - 1U].has_active = false;
}

}  // namespace drivegate::canopen
