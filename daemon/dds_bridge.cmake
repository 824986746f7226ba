# Included from daemon/CMakeLists.txt: the DDS bridge (daemon/dds_bridge.*).
find_package(spdlog REQUIRED)
add_library(drivegate_dds_bridge STATIC ${CMAKE_CURRENT_LIST_DIR}/dds_bridge.cpp)
target_include_directories(drivegate_dds_bridge PUBLIC ${PROJECT_SOURCE_DIR})
target_link_libraries(drivegate_dds_bridge
  PUBLIC drivegate_core Threads::Threads
  PRIVATE drivegate_dds spdlog::spdlog drivegate_warnings)
