#include "config/xml_text.hpp"

#include <tinyxml2.h>

#include <algorithm>
#include <cctype>

namespace drivegate::config {

std::string xml_child_path(const std::string& path, std::string_view name, int position) {
  std::string s = path.empty() ? std::string{name} : path + "/" + std::string{name};
  if (position > 0) s += "[" + std::to_string(position) + "]";
  return s;
}

std::string xml_parse_problem(const tinyxml2::XMLDocument& doc) {
  std::string what = tinyxml2::XMLDocument::ErrorIDToName(doc.ErrorID());
  if (what.rfind("XML_ERROR_", 0) == 0)
    what = what.substr(10);
  else if (what.rfind("XML_", 0) == 0)
    what = what.substr(4);
  std::transform(what.begin(), what.end(), what.begin(),
                 [](unsigned char c) { return c == '_' ? ' ' : static_cast<char>(std::tolower(c)); });
  return "not well-formed XML (" + what + ")";
}

}  // namespace drivegate::config
