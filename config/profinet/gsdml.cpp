#include "config/profinet/gsdml.hpp"

#include <tinyxml2.h>

#include <algorithm>
#include <array>
#include <cctype>

#include "config/scalars.hpp"
#include "config/text_util.hpp"
#include "config/xml_text.hpp"
#include "config/yaml_reader.hpp"

namespace drivegate::config {

namespace {

using tinyxml2::XMLElement;

// The C_SDU of one frame holds at most 1440 octets [IEC 61158-6-10, C_SDU length]: a submodule's
// data beyond that can never be exchanged.
constexpr int kMaxIoBytes = 1440;

// Octets of the GSDML data types that have a fixed size [GSDML spec, DataItem DataType];
// OctetString and VisibleString take a Length attribute.
struct DataType {
  std::string_view name;
  int bytes;
};
constexpr std::array<DataType, 26> kDataTypes{{
    {"Integer8", 1},   {"Integer16", 2},  {"Integer32", 4},    {"Integer64", 8},  {"Unsigned8", 1},
    {"Unsigned16", 2}, {"Unsigned32", 4}, {"Unsigned64", 8},   {"Float32", 4},    {"Float64", 8},
    {"N2", 2},         {"N4", 4},         {"V2", 2},           {"E2", 2},         {"C4", 4},
    {"X2", 2},         {"X4", 4},         {"Unipolar2.16", 2}, {"Date", 7},       {"TimeOfDay with date indication", 6},
    {"TimeOfDay without date indication", 4}, {"TimeDifference with date indication", 6},
    {"TimeDifference without date indication", 4}, {"F_MessageTrailer4Byte", 4}, {"F_MessageTrailer5Byte", 5},
    {"Float32+Unsigned8", 5},
}};

class Parser {
 public:
  Parser(const std::string& label, Problems& problems) : label_(label), problems_(problems) {}

  std::optional<GsdmlFile> run(std::string_view text) {
    tinyxml2::XMLDocument doc;
    if (doc.Parse(text.data(), text.size()) != tinyxml2::XML_SUCCESS) {
      error(doc.ErrorLineNum(), "", xml_parse_problem(doc));
      return std::nullopt;
    }
    const XMLElement* root = doc.RootElement();
    if (root == nullptr || std::string_view{root->Name()} != "ISO15745Profile") {
      error(root ? root->GetLineNum() : 0, "",
            "the root element is <" + std::string{root ? root->Name() : ""} +
                ">, not <ISO15745Profile>: this is not a GSDML file");
      return std::nullopt;
    }
    GsdmlFile out;
    const XMLElement* body = root->FirstChildElement("ProfileBody");
    const XMLElement* identity = body ? body->FirstChildElement("DeviceIdentity") : nullptr;
    if (identity == nullptr) {
      error(root, "ProfileBody", "has no DeviceIdentity");
    } else {
      out.vendor_id = static_cast<std::uint16_t>(number(identity, "ProfileBody/DeviceIdentity", "VendorID", 0xFFFF).value_or(0));
      out.device_id = static_cast<std::uint16_t>(number(identity, "ProfileBody/DeviceIdentity", "DeviceID", 0xFFFF).value_or(0));
    }
    const XMLElement* process = body ? body->FirstChildElement("ApplicationProcess") : nullptr;
    const XMLElement* dap_list = process ? process->FirstChildElement("DeviceAccessPointList") : nullptr;
    modules(dap_list, "DeviceAccessPointItem", "DeviceAccessPointList", out.daps);
    if (out.daps.empty() && errors_ == 0)
      error(dap_list ? dap_list : root, "ProfileBody/ApplicationProcess/DeviceAccessPointList",
            "lists no DeviceAccessPointItem");
    const XMLElement* module_list = process ? process->FirstChildElement("ModuleList") : nullptr;
    modules(module_list, "ModuleItem", "ModuleList", out.modules);
    if (errors_ > 0) return std::nullopt;
    return out;
  }

 private:
  void error(int line, const std::string& path, std::string message) {
    ++errors_;
    problems_.error(Diagnostic{label_, line, line > 0 ? 1 : 0, path, std::move(message)});
  }
  void error(const XMLElement* at, const std::string& path, std::string message) {
    error(at ? at->GetLineNum() : 0, path, std::move(message));
  }

  // A required numeric attribute, 0x hex or decimal, at most `max`.
  std::optional<std::uint64_t> number(const XMLElement* e, const std::string& path, const char* attribute,
                                      std::uint64_t max) {
    const char* text = e->Attribute(attribute);
    if (text == nullptr) {
      error(e, path, std::string{"has no "} + attribute);
      return std::nullopt;
    }
    const auto v = parse_integer(text);
    if (!v || *v < 0 || static_cast<std::uint64_t>(*v) > max) {
      error(e, path, std::string{attribute} + " must be a number in 0.." + std::to_string(max) + " (decimal or 0x hex), got " +
                         in_quotes(text));
      return std::nullopt;
    }
    return static_cast<std::uint64_t>(*v);
  }

  // The octets of Input or Output: the sum of its DataItems.
  int io_bytes(const XMLElement* io, const std::string& path) {
    if (io == nullptr) return 0;
    int total = 0;
    int position = 0;
    for (const XMLElement* d = io->FirstChildElement("DataItem"); d != nullptr; d = d->NextSiblingElement("DataItem")) {
      const std::string at = xml_child_path(path, "DataItem", ++position);
      const char* type = d->Attribute("DataType");
      if (type == nullptr) {
        error(d, at, "has no DataType");
        continue;
      }
      const std::string_view t{type};
      int bytes = 0;
      if (t == "OctetString" || t == "VisibleString") {
        const auto length = number(d, at, "Length", kMaxIoBytes);
        if (length && *length == 0) error(d, at, "Length must be at least 1");
        bytes = static_cast<int>(length.value_or(0));
      } else {
        const auto it = std::find_if(kDataTypes.begin(), kDataTypes.end(), [&](const DataType& x) { return x.name == t; });
        if (it == kDataTypes.end()) {
          error(d, at, "DataType " + in_quotes(t) + " is not a GSDML data type with a known size");
          continue;
        }
        bytes = it->bytes;
      }
      total += bytes;
      if (total > kMaxIoBytes) {
        error(d, at, "the data reach " + std::to_string(total) + " octets, more than the " +
                         std::to_string(kMaxIoBytes) + " one frame can carry");
        return 0;
      }
    }
    return total;
  }

  void submodules(const XMLElement* module, const std::string& path, GsdmlModule& out) {
    const XMLElement* list = module->FirstChildElement("VirtualSubmoduleList");
    int position = 0;
    for (const XMLElement* s = list ? list->FirstChildElement("VirtualSubmoduleItem") : nullptr; s != nullptr;
         s = s->NextSiblingElement("VirtualSubmoduleItem")) {
      const std::string at = xml_child_path(xml_child_path(path, "VirtualSubmoduleList"), "VirtualSubmoduleItem", ++position);
      GsdmlSubmodule sub;
      sub.line = s->GetLineNum();
      sub.id = s->Attribute("ID") ? s->Attribute("ID") : "";
      sub.ident = static_cast<std::uint32_t>(number(s, at, "SubmoduleIdentNumber", 0xFFFFFFFF).value_or(0));
      // One subslot named: where it goes. A list or range ("1..3") leaves the numbering to the file order.
      if (const char* fixed = s->Attribute("FixedInSubslots"))
        if (const auto n = parse_integer(fixed); n && *n >= 1 && *n <= 0x7FFF) sub.fixed_subslot = static_cast<int>(*n);
      if (const XMLElement* io = s->FirstChildElement("IOData")) {
        sub.input_bytes = io_bytes(io->FirstChildElement("Input"), xml_child_path(at, "IOData/Input"));
        sub.output_bytes = io_bytes(io->FirstChildElement("Output"), xml_child_path(at, "IOData/Output"));
      }
      out.submodules.push_back(std::move(sub));
    }
  }

  void modules(const XMLElement* list, const char* item, const std::string& list_path, std::vector<GsdmlModule>& out) {
    int position = 0;
    for (const XMLElement* m = list ? list->FirstChildElement(item) : nullptr; m != nullptr; m = m->NextSiblingElement(item)) {
      const std::string at = xml_child_path(list_path, item, ++position);
      GsdmlModule module;
      module.line = m->GetLineNum();
      if (const char* id = m->Attribute("ID"))
        module.id = id;
      else
        error(m, at, "has no ID");
      module.ident = static_cast<std::uint32_t>(number(m, at, "ModuleIdentNumber", 0xFFFFFFFF).value_or(0));
      submodules(m, at, module);
      if (!module.id.empty() && find_gsdml_module(out, module.id) != nullptr)
        error(m, at, "ID " + in_quotes(module.id) + " is used twice");
      out.push_back(std::move(module));
    }
  }

  const std::string& label_;
  Problems& problems_;
  int errors_ = 0;
};

}  // namespace

std::optional<GsdmlFile> load_gsdml(const std::filesystem::path& file, Problems& problems) {
  const auto text = read_text_file(file.string(), Source{file.string(), &problems}, kMaxGsdmlBytes);
  if (!text) return std::nullopt;
  return load_gsdml_text(*text, file.string(), problems);
}

std::optional<GsdmlFile> load_gsdml_text(std::string_view text, const std::string& label, Problems& problems) {
  return Parser{label, problems}.run(text);
}

const GsdmlModule* find_gsdml_module(const std::vector<GsdmlModule>& modules, std::string_view id) noexcept {
  const auto it = std::find_if(modules.begin(), modules.end(), [&](const GsdmlModule& m) { return m.id == id; });
  return it == modules.end() ? nullptr : &*it;
}

}  // namespace drivegate::config
