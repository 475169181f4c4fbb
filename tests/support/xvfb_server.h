#pragma once
// A private Xvfb server for the tests that open real windows (tests/gl's
// window test, tests/gui's scripted runs of the app): one definition instead
// of one per test program.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstdlib>
#include <string>
#include <utility>

namespace accelviz::test_support {

// Starts Xvfb (the program `xvfb`, one screen of `screen`, e.g. "640x480x24")
// for this process and points DISPLAY at it. With -displayfd the server
// takes the first free display number itself and writes it to the pipe, so
// parallel test runs never race for a number.
class PrivateXServer : public ::testing::Environment {
 public:
  PrivateXServer(std::string xvfb, std::string screen) : xvfb_(std::move(xvfb)), screen_(std::move(screen)) {}

  void SetUp() override {
    int fds[2];
    ASSERT_EQ(::pipe(fds), 0);
    pid_ = ::fork();
    ASSERT_GE(pid_, 0);
    if (pid_ == 0) {
      ::close(fds[0]);
      const int devnull = ::open("/dev/null", O_WRONLY);
      ::dup2(devnull, STDOUT_FILENO);
      ::dup2(devnull, STDERR_FILENO);
      const std::string fd = std::to_string(fds[1]);
      // -noreset: without it the server resets whenever its last client
      // leaves (each test closes GLFW, each scripted run its window), and a
      // test connecting during the reset fails to open the display.
      ::execl(xvfb_.c_str(), "Xvfb", "-displayfd", fd.c_str(), "-screen", "0", screen_.c_str(), "-nolisten", "tcp",
              "-noreset", static_cast<char*>(nullptr));
      ::_exit(127);
    }
    ::close(fds[1]);
    std::string number;
    pollfd p{fds[0], POLLIN, 0};
    while (::poll(&p, 1, 20000) > 0) {
      char c = 0;
      if (::read(fds[0], &c, 1) != 1 || c == '\n') break;
      number += c;
    }
    ::close(fds[0]);
    ASSERT_FALSE(number.empty()) << "Xvfb (" << xvfb_ << ") did not start";
    ::setenv("DISPLAY", (":" + number).c_str(), 1);
  }
  void TearDown() override {
    if (pid_ > 0) {
      ::kill(pid_, SIGTERM);
      ::waitpid(pid_, nullptr, 0);
    }
  }

 private:
  std::string xvfb_;
  std::string screen_;
  pid_t pid_ = -1;
};

}  // namespace accelviz::test_support
