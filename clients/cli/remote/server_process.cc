#include "clients/cli/remote/server_process.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fmt/core.h>
#include <spdlog/spdlog.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <stdexcept>

namespace tubepick::cli {
namespace {

constexpr std::size_t kTailLines = 50;
constexpr const char* kListening = "listening on ";

/// Exit status of a waitpid status word.
int ExitStatus(int status) {
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return -1;
}

}  // namespace

std::string SiblingExecutable(const std::string& name) {
  std::error_code error;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
  if (error) throw std::runtime_error(fmt::format("cannot resolve /proc/self/exe: {}", error.message()));
  return (self.parent_path() / name).string();
}

std::unique_ptr<ServerProcess> ServerProcess::Start(const std::string& binary,
                                                    const std::vector<std::string>& args,
                                                    std::chrono::milliseconds startup_timeout) {
  if (::access(binary.c_str(), X_OK) != 0)
    throw std::runtime_error(
        fmt::format("server binary {} is not executable ({}); build it (target "
                    "tubepick-server) or pass --server HOST:PORT",
                    binary, std::strerror(errno)));
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) throw std::runtime_error(fmt::format("pipe: {}", std::strerror(errno)));
  std::vector<std::string> argv_strings{binary};
  argv_strings.insert(argv_strings.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : argv_strings) argv.push_back(a.data());
  argv.push_back(nullptr);

  const pid_t parent = ::getpid();
  // PR_SET_PDEATHSIG follows the thread that forked: only a child of the main thread (which lives
  // as long as the process) can die with its parent; a fault campaign's restart thread cannot.
  const bool die_with_parent = ::gettid() == parent;
  const pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error(fmt::format("fork: {}", std::strerror(errno)));
  if (pid == 0) {  // child: stdout and stderr into the pipe, then exec
    // Its own process group: a Ctrl-C at the terminal reaches the parent only, which stops the
    // round safely and then this server. And it dies with the parent (SIGTERM: it drains).
    ::setpgid(0, 0);
    if (die_with_parent) {
      ::prctl(PR_SET_PDEATHSIG, SIGTERM);
      if (::getppid() != parent) ::_exit(0);  // the parent died before prctl
    }
    ::dup2(fds[1], STDOUT_FILENO);
    ::dup2(fds[1], STDERR_FILENO);
    ::execv(binary.c_str(), argv.data());
    ::_exit(127);
  }
  ::close(fds[1]);

  std::unique_ptr<ServerProcess> process(new ServerProcess());
  process->pid_ = pid;
  process->output_fd_ = fds[0];

  // Read until the listening line, the child's exit or the timeout.
  const auto deadline = std::chrono::steady_clock::now() + startup_timeout;
  std::string buffer;
  for (;;) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) break;
    pollfd p{fds[0], POLLIN, 0};
    const int ready = ::poll(&p, 1, static_cast<int>(left.count()));
    if (ready < 0 && errno == EINTR) continue;
    if (ready <= 0) break;
    char chunk[4096];
    const ssize_t n = ::read(fds[0], chunk, sizeof chunk);
    if (n <= 0) break;  // EOF: the child exited
    buffer.append(chunk, static_cast<std::size_t>(n));
    std::size_t newline;
    while ((newline = buffer.find('\n')) != std::string::npos) {
      const std::string line = buffer.substr(0, newline);
      buffer.erase(0, newline + 1);
      spdlog::debug("server: {}", line);
      process->tail_.push_back(line);
      if (process->tail_.size() > kTailLines) process->tail_.pop_front();
      const std::size_t at = line.find(kListening);
      if (at != std::string::npos && process->address_.empty()) {
        const std::size_t begin = at + std::strlen(kListening);
        process->address_ = line.substr(begin, line.find_first_of(" \t(", begin) - begin);
      }
    }
    if (!process->address_.empty()) break;
  }
  process->partial_ = buffer;
  if (process->address_.empty()) {
    const std::string tail = process->Tail();
    process->Stop(std::chrono::milliseconds(2000));
    throw std::runtime_error(
        fmt::format("{} did not report \"listening on HOST:PORT\" within {} ms; its output:\n{}", binary,
                    startup_timeout.count(), tail));
  }
  process->drain_ = std::thread([p = process.get()] { p->Drain(); });
  spdlog::info("started {} (pid {}) on {}", binary, pid, process->address_);
  return process;
}

void ServerProcess::Drain() {
  char chunk[4096];
  for (;;) {
    const ssize_t n = ::read(output_fd_, chunk, sizeof chunk);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;
    std::lock_guard<std::mutex> lock(mutex_);
    partial_.append(chunk, static_cast<std::size_t>(n));
    std::size_t newline;
    while ((newline = partial_.find('\n')) != std::string::npos) {
      std::string line = partial_.substr(0, newline);
      partial_.erase(0, newline + 1);
      spdlog::debug("server: {}", line);
      tail_.push_back(std::move(line));
      if (tail_.size() > kTailLines) tail_.pop_front();
    }
  }
}

std::string ServerProcess::Tail() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::string out;
  for (const std::string& line : tail_) out += line + "\n";
  return out;
}

int ServerProcess::Stop(std::chrono::milliseconds grace) {
  if (pid_ > 0) {
    ::kill(pid_, SIGTERM);
    const auto deadline = std::chrono::steady_clock::now() + grace;
    int status = 0;
    for (;;) {
      const pid_t done = ::waitpid(pid_, &status, WNOHANG);
      if (done == pid_) {
        exit_status_ = ExitStatus(status);
        break;
      }
      if (done < 0 && errno != EINTR) break;
      if (std::chrono::steady_clock::now() >= deadline) {
        spdlog::warn("server pid {} did not stop within {} ms of SIGTERM; SIGKILL", pid_, grace.count());
        ::kill(pid_, SIGKILL);
        if (::waitpid(pid_, &status, 0) == pid_) exit_status_ = ExitStatus(status);
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    pid_ = -1;
  }
  if (drain_.joinable()) drain_.join();  // the pipe reaches EOF once the child is gone
  if (output_fd_ >= 0) {
    ::close(output_fd_);
    output_fd_ = -1;
  }
  return exit_status_;
}

ServerProcess::~ServerProcess() { Stop(std::chrono::milliseconds(10000)); }

}  // namespace tubepick::cli
