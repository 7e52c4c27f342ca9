#pragma once

// The geodexd binary as a child process, for the process tests (tests/server) and the load bench
// (bench/load_bench.cc): stdout and stderr go to a log file, the gRPC and metrics ports are read
// from that log (start it with --listen 127.0.0.1:0 --metrics_listen 127.0.0.1:0), every wait is
// bounded, and only this child is ever signalled. Header-only, in testkit/ (the library
// geodex_testkit) so that the bench does not reach into tests/.

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <string>
#include <thread>
#include <vector>

namespace geodex::testing_support {

class GeodexdChild {
 public:
  // Starts `argv[0]` with the rest of `argv`, output to `log`, and waits (up to 60 s, or until the
  // child exits) for both listening ports in the log. port() is 0 if they never appeared.
  GeodexdChild(std::vector<std::string> argv, std::filesystem::path log) : log_(std::move(log)) {
    std::filesystem::create_directories(log_.parent_path());
    pid_ = ::fork();
    if (pid_ == 0) {
      std::FILE* out = std::freopen(log_.c_str(), "w", stdout);
      if (out == nullptr) ::_exit(126);
      ::dup2(::fileno(out), 2);
      std::vector<char*> args;
      for (std::string& a : argv) args.push_back(a.data());
      args.push_back(nullptr);
      ::execv(args[0], args.data());
      ::_exit(127);
    }
    const std::regex grpc_port("listening on port ([0-9]+)");
    const std::regex metrics_port("127.0.0.1:([0-9]+)/metrics");
    for (int i = 0; i < 1200 && (port_ == 0 || metrics_port_ == 0) && Running(); ++i) {
      const std::string text = Log();
      std::smatch m;
      if (std::regex_search(text, m, grpc_port)) port_ = std::stoi(m[1]);
      if (std::regex_search(text, m, metrics_port)) metrics_port_ = std::stoi(m[1]);
      if (port_ == 0 || metrics_port_ == 0)
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  }
  GeodexdChild(const GeodexdChild&) = delete;
  GeodexdChild& operator=(const GeodexdChild&) = delete;
  ~GeodexdChild() {
    if (pid_ > 0 && !exited_) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
  }

  bool Running() {
    int status = 0;
    if (!exited_ && ::waitpid(pid_, &status, WNOHANG) == pid_) exited_ = true;
    return !exited_;
  }
  // SIGTERM, then the exit status (128 + signal if killed by one), or -1 if it had not exited
  // after `seconds` (the destructor then kills it).
  int Terminate(double seconds) {
    ::kill(pid_, SIGTERM);
    for (int i = 0; i < seconds * 20; ++i) {
      int status = 0;
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        exited_ = true;
        return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return -1;
  }
  std::string Log() const {
    std::ifstream in(log_);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  }

  pid_t pid() const { return pid_; }
  int port() const { return port_; }
  int metrics_port() const { return metrics_port_; }

 private:
  std::filesystem::path log_;
  pid_t pid_ = -1;
  bool exited_ = false;
  int port_ = 0;
  int metrics_port_ = 0;
};

}  // namespace geodex::testing_support
