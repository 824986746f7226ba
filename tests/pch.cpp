// The translation unit that carries the test executables' shared precompiled <gtest/gtest.h>
// (DRIVEGATE_PCH, tests/CMakeLists.txt); it has no code of its own.
