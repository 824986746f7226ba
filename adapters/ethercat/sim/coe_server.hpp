#pragma once
// The CoE server of a simulated slave [ETG.1000.6 §5.6]: SDO upload/download (expedited, normal,
// segmented), aborts with the CiA 301 codes, SDO information (OD list, object and entry
// descriptions), over an ObjectDictionary. Replies go into a MailboxOutbox, the fixed queue of
// slave -> master mailboxes the ESC hands to SM1 one at a time.
//
// Protocol errors: a segment without an initiate or an unknown command specifier aborts with
// 05040001h, a wrong toggle with 05030000h, complete access with 06010000h (not offered). Nothing
// here allocates after construction.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "adapters/ethercat/sim/object_dictionary.hpp"
#include "adapters/ethercat/wire/mailbox.hpp"
#include "adapters/ethercat/wire/registers.hpp"

namespace drivegate::ethercat::sim {

// Fixed-capacity FIFO of whole mailboxes (header included), each at most `mailbox_size` bytes.
class MailboxOutbox {
 public:
  MailboxOutbox(std::size_t capacity, std::size_t mailbox_size);
  // Queues the next message: `encode(buf)` writes it into `buf` (zeroed, mailbox_size() bytes)
  // and returns the bytes written (0: could not encode). The mailbox counter is stamped [ETG.1000.6
  // mailbox header: 1..7, each new message takes the next one]. False, and the message counted in
  // dropped(), when the outbox is full or the encoding failed.
  template <class Encode>
  bool emit(Encode&& encode) noexcept {
    const std::span<std::uint8_t> buf = reserve();
    if (!buf.empty() && commit(encode(buf))) return true;
    ++dropped_;
    return false;
  }
  // Puts a message back at the front (a repeat request, see EscSlave), counter unchanged.
  bool push_front(std::span<const std::uint8_t> msg) noexcept;
  bool empty() const noexcept { return count_ == 0; }
  bool full() const noexcept { return count_ == slots_.size(); }
  std::span<const std::uint8_t> front() const noexcept;
  void pop() noexcept;
  // Pops the front message without delivering it (counted in dropped()).
  void drop_front() noexcept;
  void clear() noexcept;
  // Messages lost: the outbox was full, the encoding failed, or drop_front().
  std::uint64_t dropped() const noexcept { return dropped_; }
  std::size_t mailbox_size() const noexcept { return mailbox_size_; }

 private:
  struct Slot {
    std::vector<std::uint8_t> bytes;
    std::size_t size = 0;
  };
  // Space for the next message (empty when full); commit() queues the bytes written (false when
  // `size` is not a whole mailbox that fits).
  std::span<std::uint8_t> reserve() noexcept;
  bool commit(std::size_t size) noexcept;

  std::vector<Slot> slots_;
  std::size_t mailbox_size_ = 0;
  std::size_t head_ = 0;
  std::size_t count_ = 0;
  std::uint8_t counter_ = 0;
  std::uint64_t dropped_ = 0;
};

class CoeServer {
 public:
  // `od` may be null (every SDO aborts with 06020000h). `max_object_bytes`: the largest value a
  // segmented transfer carries (buffer allocated here).
  CoeServer(ObjectDictionary* od, std::size_t max_object_bytes = 1024);

  // One CoE request (the whole SM0 mailbox). Replies are queued in `out`; none when it is full.
  void on_request(std::span<const std::uint8_t> mailbox, AlState state, MailboxOutbox& out) noexcept;
  // Forgets an open segmented transfer (the slave went to INIT).
  void reset() noexcept;

 private:
  void sdo(std::span<const std::uint8_t> mailbox, AlState state, MailboxOutbox& out) noexcept;
  void info(std::span<const std::uint8_t> mailbox, MailboxOutbox& out) noexcept;
  void abort(MailboxOutbox& out, std::uint16_t index, std::uint8_t subindex, std::uint32_t code) noexcept;
  void upload_segment(bool toggle, MailboxOutbox& out) noexcept;

  enum class Transfer : std::uint8_t { None, Upload, Download };
  ObjectDictionary* od_ = nullptr;
  std::vector<std::uint8_t> buffer_;
  Transfer transfer_ = Transfer::None;
  std::uint16_t index_ = 0;
  std::uint8_t subindex_ = 0;
  std::size_t size_ = 0;    // complete size of the open transfer
  std::size_t done_ = 0;    // bytes transferred so far
  bool toggle_ = false;     // toggle the next segment must carry
  std::array<std::uint16_t, 512> list_{};
};

}  // namespace drivegate::ethercat::sim
