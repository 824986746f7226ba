#pragma once
// What the XML readers of vendor files (EtherCAT ESI, PROFINET GSDML; tinyxml2) say in their
// problems: where an element is, and why a file is not XML at all.
#include <string>
#include <string_view>

namespace tinyxml2 {
class XMLDocument;
}

namespace drivegate::config {

// "Path/Name", with "[position]" when position > 0 (the position-th element of that name).
std::string xml_child_path(const std::string& path, std::string_view name, int position = 0);

// "not well-formed XML (mismatched element)" for a document whose Parse() failed.
std::string xml_parse_problem(const tinyxml2::XMLDocument& doc);

}  // namespace drivegate::config
