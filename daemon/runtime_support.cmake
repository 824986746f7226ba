# Cycle threads, real-time set-up and systemd notification for the daemon. Included from
# daemon/CMakeLists.txt; a library of its own so tests and benchmarks can link it without the
# daemon.
add_library(drivegate_runtime_support STATIC
  ${CMAKE_CURRENT_LIST_DIR}/cycle_thread.cpp
  ${CMAKE_CURRENT_LIST_DIR}/realtime.cpp
  ${CMAKE_CURRENT_LIST_DIR}/systemd_notify.cpp
)
target_include_directories(drivegate_runtime_support PUBLIC ${PROJECT_SOURCE_DIR})
target_link_libraries(drivegate_runtime_support
  PUBLIC drivegate_core Threads::Threads
  PRIVATE PkgConfig::SYSTEMD drivegate_warnings)
