#pragma once
// The object dictionary a simulated EtherCAT slave's CoE server works on [ETG.1000.6 §5.6: SDO
// services address objects by index/subindex with the CiA 301 abort codes; §5.6.3: SDO
// information describes objects and entries]. `ObjectDictionary` is the extension point a slave
// application implements (a CiA 402 drive model plugs its own in); `SimpleObjectDictionary` is a
// fixed table filled at construction that tests and the generic slaves use.
//
// Values are little-endian bytes. Nothing here allocates after the table is built.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "adapters/ethercat/wire/mailbox.hpp"
#include "adapters/ethercat/wire/registers.hpp"
#include "profiles/cia402/sdo_abort.hpp"

namespace drivegate::ethercat::sim {

struct OdReadResult {
  std::uint32_t abort_code = 0;  // 0 = ok
  std::size_t size = 0;          // bytes written to `out`
};

class ObjectDictionary {
 public:
  virtual ~ObjectDictionary() = default;
  // Reads an entry's value into `out` (the caller offers at least the largest entry the
  // dictionary holds; a larger value fails with kOutOfMemory). `state` is the slave's AL state
  // for the access rights [ETG.1000.6 §5.6.3.6 object access bits].
  virtual OdReadResult read(std::uint16_t index, std::uint8_t subindex, std::span<std::uint8_t> out,
                            AlState state) noexcept = 0;
  // Writes a value; the length must match the entry's (kTooLong/kTooShort otherwise).
  virtual std::uint32_t write(std::uint16_t index, std::uint8_t subindex, std::span<const std::uint8_t> data,
                              AlState state) noexcept = 0;
  // SDO information [ETG.1000.6 §5.6.3]. list(): indexes of the list type, in ascending order, up
  // to out.size() (returns the total, which may be larger). Descriptions: false when absent.
  virtual std::size_t list(OdListType type, std::span<std::uint16_t> out) const noexcept = 0;
  virtual bool describe_object(std::uint16_t index, SdoInfoObjectDescription& out) const noexcept = 0;
  virtual bool describe_entry(std::uint16_t index, std::uint8_t subindex, SdoInfoEntryDescription& out) const noexcept = 0;
};

// CoE data types [ETG.1000.6 Table 64 / CiA 301 §7.4.7] the simple dictionary names.
namespace data_type {
inline constexpr std::uint16_t kBoolean = 0x0001;
inline constexpr std::uint16_t kInteger8 = 0x0002;
inline constexpr std::uint16_t kInteger16 = 0x0003;
inline constexpr std::uint16_t kInteger32 = 0x0004;
inline constexpr std::uint16_t kUnsigned8 = 0x0005;
inline constexpr std::uint16_t kUnsigned16 = 0x0006;
inline constexpr std::uint16_t kUnsigned32 = 0x0007;
inline constexpr std::uint16_t kVisibleString = 0x0009;
inline constexpr std::uint16_t kOctetString = 0x000A;
}  // namespace data_type

struct OdEntrySpec {
  std::uint16_t index = 0;
  std::uint8_t subindex = 0;
  std::uint16_t data_type = 0;
  std::uint16_t access = 0;                 // object_access bits
  std::string_view name{};
  std::span<const std::uint8_t> value{};    // initial value; its size is the entry's fixed size
};

class SimpleObjectDictionary final : public ObjectDictionary {
 public:
  // Objects whose entries are added under one index; `object_code` (object_code::kVariable ...)
  // and `name` describe the object. Call before any frame passes (allocates).
  void add_object(std::uint16_t index, std::uint8_t object_code, std::string_view name);
  void add_entry(const OdEntrySpec& e);
  // Convenience: a VAR object with one subindex-0 entry.
  void add_variable(std::uint16_t index, std::uint16_t data_type, std::uint16_t access, std::string_view name,
                    std::span<const std::uint8_t> value);

  OdReadResult read(std::uint16_t index, std::uint8_t subindex, std::span<std::uint8_t> out,
                    AlState state) noexcept override;
  std::uint32_t write(std::uint16_t index, std::uint8_t subindex, std::span<const std::uint8_t> data,
                      AlState state) noexcept override;
  std::size_t list(OdListType type, std::span<std::uint16_t> out) const noexcept override;
  bool describe_object(std::uint16_t index, SdoInfoObjectDescription& out) const noexcept override;
  bool describe_entry(std::uint16_t index, std::uint8_t subindex, SdoInfoEntryDescription& out) const noexcept override;

  // Direct access for the application (no access checks); empty when absent.
  std::span<std::uint8_t> value(std::uint16_t index, std::uint8_t subindex) noexcept;
  std::size_t largest_entry() const noexcept { return largest_; }

 private:
  struct Object {
    std::uint16_t index = 0;
    std::uint8_t object_code = 0;
    std::string_view name{};
  };
  struct Entry {
    std::uint16_t index = 0;
    std::uint8_t subindex = 0;
    std::uint16_t data_type = 0;
    std::uint16_t access = 0;
    std::string_view name{};
    std::size_t offset = 0;  // into values_
    std::size_t size = 0;
  };
  const Object* find_object(std::uint16_t index) const noexcept;
  Entry* find_entry(std::uint16_t index, std::uint8_t subindex) noexcept;
  const Entry* find_entry(std::uint16_t index, std::uint8_t subindex) const noexcept;

  std::vector<Object> objects_;  // sorted by index
  std::vector<Entry> entries_;   // sorted by index, subindex
  std::vector<std::uint8_t> values_;
  std::size_t largest_ = 0;
};

}  // namespace drivegate::ethercat::sim
