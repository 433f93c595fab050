// Figures a test measures, reported through gtest rather than bare stdout: SKYBAKE_LOG takes a
// printf format, collects the text up to each newline and, per complete line, records it as a
// property of the running test (figure_1, figure_2, ... in --gtest_output=xml or json) and
// prints it behind a "[  FIGURE  ]" tag (what `ctest -V` and --output-on-failure show).
#pragma once

#include <gtest/gtest.h>

#include <cstdarg>
#include <cstdio>
#include <mutex>
#include <string>
#include <vector>

namespace skybake::test {

inline void Log(const char* format, ...) __attribute__((format(printf, 1, 2)));

inline void Log(const char* format, ...) {
  va_list args;
  va_start(args, format);
  va_list size_args;
  va_copy(size_args, args);
  const int n = std::vsnprintf(nullptr, 0, format, size_args);
  va_end(size_args);
  std::vector<char> text(n > 0 ? static_cast<size_t>(n) + 1 : 1, '\0');
  if (n > 0) std::vsnprintf(text.data(), text.size(), format, args);
  va_end(args);

  static std::mutex mutex;
  static std::string pending;
  static const ::testing::TestInfo* test = nullptr;
  static int count = 0;
  const std::lock_guard<std::mutex> lock(mutex);
  const ::testing::TestInfo* current = ::testing::UnitTest::GetInstance()->current_test_info();
  if (current != test) {
    test = current;
    count = 0;
  }
  pending += text.data();
  for (size_t end; (end = pending.find('\n')) != std::string::npos;) {
    const std::string line = pending.substr(0, end);
    pending.erase(0, end + 1);
    if (line.find_first_not_of(' ') == std::string::npos) continue;
    ::testing::Test::RecordProperty("figure_" + std::to_string(++count), line);
    std::printf("[  FIGURE  ] %s\n", line.c_str());
  }
}

}  // namespace skybake::test

#define SKYBAKE_LOG(...) ::skybake::test::Log(__VA_ARGS__)
