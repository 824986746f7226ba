#pragma once
// A core::ControllerSink that records every reply, event and parameter reply of an axis
// controller, for the profile master tests (CiA 402, PROFIdrive). It allocates: not for the
// no-allocation tests.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/axis_controller.hpp"

namespace drivegate::test {

struct RecordingSink final : core::ControllerSink {
  struct Failure {
    core::CommandId id;
    std::string reason;
  };
  struct Ev {
    core::EventKind kind;
    std::uint32_t code;
    std::string text;
  };
  std::vector<core::CommandId> completed_ids;
  std::vector<Failure> failures;
  std::vector<Ev> events;
  std::vector<core::ParamReply> params;

  void completed(core::CommandId id) noexcept override { completed_ids.push_back(id); }
  void failed(core::CommandId id, std::string_view reason) noexcept override {
    failures.push_back({id, std::string(reason)});
  }
  void event(core::EventKind kind, std::uint32_t code, std::string_view text) noexcept override {
    events.push_back({kind, code, std::string(text)});
  }
  void parameter_done(const core::ParamReply& reply) noexcept override { params.push_back(reply); }

  [[nodiscard]] bool done(core::CommandId id) const {
    for (auto c : completed_ids) {
      if (c == id) return true;
    }
    return false;
  }
  [[nodiscard]] std::string failure(core::CommandId id) const {
    for (const auto& f : failures) {
      if (f.id == id) return f.reason;
    }
    return {};
  }
  // Final replies (completed or failed) the command got: exactly 1 once it is over.
  [[nodiscard]] std::size_t replies(core::CommandId id) const {
    std::size_t n = 0;
    for (auto c : completed_ids) n += c == id ? 1U : 0U;
    for (const auto& f : failures) n += f.id == id ? 1U : 0U;
    return n;
  }
  [[nodiscard]] std::size_t count(core::EventKind kind) const {
    std::size_t n = 0;
    for (const auto& e : events) n += e.kind == kind ? 1U : 0U;
    return n;
  }
};

}  // namespace drivegate::test
