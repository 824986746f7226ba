#include "adapters/ethercat/slave_dictionary.hpp"

#include <algorithm>
#include <cstdio>
#include <optional>
#include <vector>

#include "profiles/cia402/sdo_abort.hpp"

namespace drivegate::ethercat {

namespace {

// The profile area of axis 0 [ETG.6010 multi-axis: axis n's at + n x axis_offset].
constexpr std::uint16_t kProfileArea = 0x6000;
constexpr std::uint16_t kProfileAreaSize = 0x800;

bool separator(char c) noexcept { return c == ' ' || c == '_' || c == '\t'; }

// Names compared as people type them: letters without case, spaces and underscores alike, runs of
// them as one, none at either end ("position_actual_value" = "Position actual value").
bool same_name(std::string_view a, std::string_view b) noexcept {
  const auto next = [](std::string_view s, std::size_t& i) -> int {
    if (i < s.size() && separator(s[i])) {
      while (i < s.size() && separator(s[i])) ++i;
      return i < s.size() ? ' ' : -1;
    }
    if (i >= s.size()) return -1;
    const char c = s[i++];
    return c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : static_cast<unsigned char>(c);
  };
  std::size_t i = 0, j = 0;
  while (i < a.size() && separator(a[i])) ++i;
  while (j < b.size() && separator(b[j])) ++j;
  for (;;) {
    const int x = next(a, i);
    const int y = next(b, j);
    if (x != y) return false;
    if (x < 0) return true;
  }
}

// The object as `axis` numbers it, or none when it is another axis' of a multi-axis slave.
std::optional<std::uint16_t> on_axis(std::uint16_t index, const DictionaryAxis& axis) noexcept {
  if (axis.axes <= 1 || axis.axis_offset == 0 || index < kProfileArea) return index;
  const auto rel = static_cast<unsigned>(index - kProfileArea);
  const unsigned offset = axis.axis_offset;
  const unsigned owner = rel / offset;
  if (owner >= static_cast<unsigned>(axis.axes) || rel % offset >= kProfileAreaSize) return index;
  if (owner != static_cast<unsigned>(axis.slave_axis)) return std::nullopt;
  return static_cast<std::uint16_t>(index - owner * offset);
}

std::string slave_text(std::uint16_t position) { return "slave " + std::to_string(position); }

}  // namespace

SlaveDictionary::SlaveDictionary(std::uint16_t position)
    : position_(position),
      list_(std::make_unique<std::uint16_t[]>(kMaxObjects)),
      object_(std::make_unique<Object[]>(kMaxObjects)),
      entry_(std::make_unique<Entry[]>(kMaxEntries)),
      names_(std::make_unique<char[]>(kNameBytes)) {}

bool SlaveDictionary::start(bool sdo_info) noexcept {
  resetting_.store(true, std::memory_order_seq_cst);
  if (readers_.load(std::memory_order_seq_cst) != 0) {
    resetting_.store(false, std::memory_order_seq_cst);
    return false;
  }
  objects_.store(0, std::memory_order_relaxed);
  listed_.store(0, std::memory_order_relaxed);
  progress_.store(0, std::memory_order_relaxed);
  failure_.store(0, std::memory_order_relaxed);
  step_ = Step::List;
  listed_count_ = 0;
  next_ = 0;
  entries_used_ = 0;
  names_used_ = 0;
  state_.store(sdo_info ? State::Reading : State::Unsupported, std::memory_order_release);
  resetting_.store(false, std::memory_order_seq_cst);
  return true;
}

void SlaveDictionary::stop(CoeSdoClient* coe) noexcept {
  if (id_ != 0 && coe != nullptr) coe->take(id_);
  id_ = 0;
  // A reading cut short starts over at the next OP.
  if (state() == State::Reading) state_.store(State::NotYet, std::memory_order_release);
}

std::span<char> SlaveDictionary::name_room() noexcept {
  return {names_.get() + names_used_, std::min(kMaxName, kNameBytes - names_used_)};
}

void SlaveDictionary::step(CoeSdoClient& coe) noexcept {
  if (state() != State::Reading) return;
  if (id_ != 0) {
    take_result(coe);
    if (id_ != 0 || state() != State::Reading) return;
  }
  // Client requests go first: one of ours only into an otherwise idle mailbox.
  if (coe.pending() != 0) return;
  if (step_ != Step::List && (names_used_ >= kNameBytes || (step_ == Step::Entry && entries_used_ >= kMaxEntries))) {
    finish(State::Full);
    return;
  }
  switch (step_) {
    case Step::List: id_ = coe.od_list(OdListType::All, std::span<std::uint16_t>(list_.get(), kMaxObjects)); break;
    case Step::Object: id_ = coe.object_description(list_[next_], name_room()); break;
    case Step::Entry: id_ = coe.entry_description(building_.index, sub_, name_room()); break;
  }
}

void SlaveDictionary::take_result(CoeSdoClient& coe) noexcept {
  const CoeSdoResult r = coe.result(id_);
  if (r.status == CoeSdoStatus::Queued || r.status == CoeSdoStatus::InFlight) return;
  if (r.status != CoeSdoStatus::Unknown) coe.take(id_);
  id_ = 0;
  const bool done = r.status == CoeSdoStatus::Done;
  // A name cut because the arena is nearly full: the table is full (a name cut at kMaxName is
  // kept as it is).
  const bool full = done && r.info.name_truncated && name_room().size() < kMaxName;
  switch (step_) {
    case Step::List:
      if (!done) {
        failure_.store(r.abort_code, std::memory_order_relaxed);
        finish(State::Failed);
        return;
      }
      listed_count_ = std::min(r.size, kMaxObjects);
      listed_.store(listed_count_, std::memory_order_release);
      next_object();
      return;
    case Step::Object:
      if (full) {
        finish(State::Full);
        return;
      }
      if (!done) {  // an object the slave lists but does not describe: left out
        ++next_;
        next_object();
        return;
      }
      building_ = Object{};
      building_.index = list_[next_];
      building_.data_type = r.info.data_type;
      building_.object_code = r.info.object_code;
      building_.max_sub = r.info.max_subindex;
      building_.first_entry = static_cast<std::uint32_t>(entries_used_);
      building_.name_at = static_cast<std::uint32_t>(names_used_);
      building_.name_size = static_cast<std::uint16_t>(r.size);
      names_used_ += r.size;
      if (building_.object_code == object_code::kArray || building_.object_code == object_code::kRecord) {
        sub_ = 0;
        step_ = Step::Entry;
        return;
      }
      break;
    case Step::Entry:
      if (full) {
        finish(State::Full);
        return;
      }
      // A sub-index the slave does not describe (a gap in a record) is left out.
      if (done) {
        entry_[entries_used_++] = Entry{sub_, r.info.data_type, static_cast<std::uint32_t>(names_used_),
                                        static_cast<std::uint16_t>(r.size)};
        names_used_ += r.size;
        ++building_.entry_count;
      }
      if (sub_ < building_.max_sub) {
        ++sub_;
        return;
      }
      break;
  }
  // The object is complete: published with its entries and names.
  const std::size_t n = objects_.load(std::memory_order_relaxed);
  object_[n] = building_;
  objects_.store(n + 1, std::memory_order_release);
  ++next_;
  next_object();
}

void SlaveDictionary::next_object() noexcept {
  progress_.store(next_, std::memory_order_release);
  step_ = Step::Object;
  if (next_ >= listed_count_) finish(State::Done);
}

void SlaveDictionary::finish(State s) noexcept { state_.store(s, std::memory_order_release); }

DictionaryMatch SlaveDictionary::find(std::string_view name, const DictionaryAxis& axis) const {
  // The reader guard (see the header): a start() that sees us waits; we back off from one that
  // runs.
  struct Guard {
    std::atomic<int>& n;
    explicit Guard(std::atomic<int>& r) : n(r) { n.fetch_add(1, std::memory_order_seq_cst); }
    ~Guard() { n.fetch_sub(1, std::memory_order_seq_cst); }
    Guard(const Guard&) = delete;
    Guard& operator=(const Guard&) = delete;
  } guard(readers_);
  if (resetting_.load(std::memory_order_seq_cst)) {
    DictionaryMatch m;
    m.error = "the dictionary of " + slave_text(position_) + " is being read again; use INDEX:SUB or try again";
    return m;
  }
  return lookup(name, axis);
}

DictionaryMatch SlaveDictionary::lookup(std::string_view name, const DictionaryAxis& axis) const {
  DictionaryMatch m;
  const State st = state();
  const std::string slave = slave_text(position_);
  switch (st) {
    case State::NotYet:
      m.error = "the dictionary of " + slave + " is read over SDO Information once it is in OP; use INDEX:SUB or try again";
      return m;
    case State::Unsupported:
      m.error = slave + " does not support SDO Information (mailbox CoE details in its SII); give the axis an `esi:` "
                        "file or use INDEX:SUB";
      return m;
    case State::Reading: {
      // Names resolve once the whole list is read: a name found early might turn out ambiguous.
      const std::size_t total = listed();
      m.error = "the dictionary of " + slave + " is still being read (" +
                (total == 0 ? std::string("its object list")
                            : std::to_string(progress()) + " of " + std::to_string(total) + " objects") +
                "); use INDEX:SUB or try again";
      return m;
    }
    case State::Failed: {
      m.error = "the dictionary of " + slave + " could not be read over SDO Information (object list: " +
                std::string(cia402::sdo_abort_text(failure_.load(std::memory_order_relaxed))) +
                "); give the axis an `esi:` file or use INDEX:SUB";
      return m;
    }
    case State::Done:
    case State::Full: break;
  }
  struct Candidate {
    std::uint16_t index;
    std::uint8_t sub;
    std::uint16_t data_type;
    std::string_view object, entry;
  };
  std::vector<Candidate> found;
  const std::size_t n = objects_.load(std::memory_order_acquire);
  const auto add = [&](std::uint16_t index, std::uint8_t sub, std::uint16_t type, std::string_view object,
                       std::string_view entry) {
    if (const auto own = on_axis(index, axis)) found.push_back({*own, sub, type, object, entry});
  };
  const auto composite = [](const Object& o) {
    return o.object_code == object_code::kArray || o.object_code == object_code::kRecord;
  };
  for (std::size_t i = 0; i < n; ++i) {
    const Object& o = object_[i];
    if (!composite(o) && same_name(name_of(o.name_at, o.name_size), name))
      add(o.index, 0, o.data_type, name_of(o.name_at, o.name_size), {});
  }
  // OBJECT:SUB (an object's name may itself hold a colon: every split is tried).
  for (std::size_t colon = name.find(':'); found.empty() && colon != std::string_view::npos;
       colon = name.find(':', colon + 1)) {
    const std::string_view parent = name.substr(0, colon);
    const std::string_view sub = name.substr(colon + 1);
    for (std::size_t i = 0; i < n; ++i) {
      const Object& o = object_[i];
      if (!composite(o) || !same_name(name_of(o.name_at, o.name_size), parent)) continue;
      for (std::uint32_t e = o.first_entry; e < o.first_entry + o.entry_count; ++e)
        if (same_name(name_of(entry_[e].name_at, entry_[e].name_size), sub))
          add(o.index, entry_[e].sub, entry_[e].data_type, name_of(o.name_at, o.name_size),
              name_of(entry_[e].name_at, entry_[e].name_size));
    }
  }
  if (found.size() == 1) {
    m.found = true;
    m.index = found.front().index;
    m.sub = found.front().sub;
    m.type = core::param_type_from_cia(found.front().data_type);
    return m;
  }
  if (found.size() > 1) {
    std::string list;
    for (const Candidate& c : found) {
      char id[16];
      std::snprintf(id, sizeof id, "%04X:%u", unsigned{c.index}, unsigned{c.sub});
      if (!list.empty()) list += ", ";
      list += std::string(id) + " '" + std::string(c.object) + (c.entry.empty() ? "" : ":" + std::string(c.entry)) + "'";
    }
    m.error = "'" + std::string(name) + "' names " + std::to_string(found.size()) + " objects in the dictionary of " +
              slave + " (" + list + "); use INDEX:SUB";
    return m;
  }
  m.error = "no object named '" + std::string(name) + "' in the dictionary of " + slave + " (" + std::to_string(n) +
            " objects read over SDO Information" +
            (st == State::Full ? ", of " + std::to_string(listed()) + ": the gateway keeps no more names" : std::string{}) +
            "; a sub-index is named OBJECT:SUB); use INDEX:SUB";
  return m;
}

}  // namespace drivegate::ethercat
