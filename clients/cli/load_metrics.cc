#include "clients/cli/load_metrics.h"

#include <fmt/core.h>
#include <netdb.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <stdexcept>

namespace tubepick::cli {
namespace {

using Clock = std::chrono::steady_clock;

struct ParsedUrl {
  std::string host;
  std::string port;
  std::string path;
};

ParsedUrl ParseHttpUrl(const std::string& url) {
  constexpr std::string_view kScheme = "http://";
  if (url.rfind(kScheme, 0) != 0)
    throw std::runtime_error("metrics URL '" + url + "': must start with http://");
  std::string rest = url.substr(kScheme.size());
  ParsedUrl out;
  const std::size_t slash = rest.find('/');
  out.path = slash == std::string::npos ? "/metrics" : rest.substr(slash);
  std::string authority = rest.substr(0, slash);
  std::size_t colon = authority.rfind(':');
  if (!authority.empty() && authority.front() == '[') {  // [v6]:port
    const std::size_t close = authority.find(']');
    if (close == std::string::npos) throw std::runtime_error("metrics URL '" + url + "': bad IPv6 host");
    out.host = authority.substr(1, close - 1);
    colon = authority.find(':', close);
  } else {
    out.host = authority.substr(0, colon);
  }
  out.port = colon == std::string::npos ? "80" : authority.substr(colon + 1);
  if (out.host.empty() || out.port.empty())
    throw std::runtime_error("metrics URL '" + url + "': no host or port");
  return out;
}

/// A connected TCP socket, closed on destruction.
class Socket {
 public:
  explicit Socket(int fd) : fd_(fd) {}
  ~Socket() {
    if (fd_ >= 0) ::close(fd_);
  }
  Socket(const Socket&) = delete;
  Socket& operator=(const Socket&) = delete;
  int fd() const { return fd_; }

 private:
  int fd_;
};

int RemainingMs(Clock::time_point deadline) {
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
  return static_cast<int>(std::max<long long>(0, left));
}

/// Waits until `fd` is ready for `events`; false on timeout.
bool WaitFor(int fd, short events, Clock::time_point deadline) {
  pollfd p{fd, events, 0};
  for (;;) {
    const int r = ::poll(&p, 1, RemainingMs(deadline));
    if (r > 0) return true;
    if (r == 0) return false;
    if (errno != EINTR) return false;
  }
}

int Connect(const ParsedUrl& u, Clock::time_point deadline, const std::string& url) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  if (const int rc = ::getaddrinfo(u.host.c_str(), u.port.c_str(), &hints, &found); rc != 0)
    throw std::runtime_error(fmt::format("{}: {}", url, ::gai_strerror(rc)));
  std::string last_error = "no address";
  int fd = -1;
  for (addrinfo* a = found; a != nullptr && fd < 0; a = a->ai_next) {
    fd = ::socket(a->ai_family, a->ai_socktype | SOCK_NONBLOCK | SOCK_CLOEXEC, a->ai_protocol);
    if (fd < 0) continue;
    if (::connect(fd, a->ai_addr, a->ai_addrlen) == 0) break;
    if (errno == EINPROGRESS && WaitFor(fd, POLLOUT, deadline)) {
      int err = 0;
      socklen_t len = sizeof(err);
      ::getsockopt(fd, SOL_SOCKET, SO_ERROR, &err, &len);
      if (err == 0) break;
      last_error = std::strerror(err);
    } else {
      last_error = errno == EINPROGRESS ? "connect timed out" : std::strerror(errno);
    }
    ::close(fd);
    fd = -1;
  }
  ::freeaddrinfo(found);
  if (fd < 0) throw std::runtime_error(url + ": " + last_error);
  return fd;
}

}  // namespace

std::string HttpGet(const std::string& url, std::chrono::milliseconds timeout) {
  const ParsedUrl u = ParseHttpUrl(url);
  const Clock::time_point deadline = Clock::now() + timeout;
  Socket socket(Connect(u, deadline, url));

  const std::string request =
      fmt::format("GET {} HTTP/1.1\r\nHost: {}:{}\r\nAccept: text/plain\r\nConnection: close\r\n\r\n", u.path,
                  u.host, u.port);
  std::size_t sent = 0;
  while (sent < request.size()) {
    if (!WaitFor(socket.fd(), POLLOUT, deadline)) throw std::runtime_error(url + ": send timed out");
    const ssize_t n = ::send(socket.fd(), request.data() + sent, request.size() - sent, MSG_NOSIGNAL);
    if (n < 0 && errno != EAGAIN && errno != EINTR)
      throw std::runtime_error(url + ": " + std::strerror(errno));
    if (n > 0) sent += static_cast<std::size_t>(n);
  }

  std::string answer;
  std::size_t header_end = std::string::npos;
  std::optional<std::size_t> content_length;
  char buffer[16384];
  for (;;) {
    if (header_end != std::string::npos && content_length && answer.size() >= header_end + *content_length)
      break;
    if (!WaitFor(socket.fd(), POLLIN, deadline)) throw std::runtime_error(url + ": read timed out");
    const ssize_t n = ::recv(socket.fd(), buffer, sizeof(buffer), 0);
    if (n == 0) break;
    if (n < 0) {
      if (errno == EAGAIN || errno == EINTR) continue;
      throw std::runtime_error(url + ": " + std::strerror(errno));
    }
    answer.append(buffer, static_cast<std::size_t>(n));
    if (header_end == std::string::npos) {
      const std::size_t blank = answer.find("\r\n\r\n");
      if (blank == std::string::npos) continue;
      header_end = blank + 4;
      std::string headers = answer.substr(0, header_end);
      std::transform(headers.begin(), headers.end(), headers.begin(),
                     [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
      if (const std::size_t at = headers.find("\r\ncontent-length:"); at != std::string::npos)
        content_length = std::strtoull(headers.c_str() + at + 17, nullptr, 10);
    }
  }
  if (header_end == std::string::npos) throw std::runtime_error(url + ": no HTTP answer");
  const std::string status_line = answer.substr(0, answer.find("\r\n"));
  if (status_line.find(" 200") == std::string::npos) throw std::runtime_error(url + ": " + status_line);
  std::string body = answer.substr(header_end);
  if (content_length && body.size() > *content_length) body.resize(*content_length);
  return body;
}

std::optional<double> PrometheusSample(std::string_view text, std::string_view name,
                                       std::string_view labels) {
  std::size_t pos = 0;
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view line = text.substr(pos, end - pos);
    pos = end + 1;
    if (line.empty() || line.front() == '#' || line.rfind(name, 0) != 0) continue;
    std::string_view rest = line.substr(name.size());
    std::string_view line_labels;
    if (!rest.empty() && rest.front() == '{') {
      const std::size_t close = rest.find('}');
      if (close == std::string_view::npos) continue;
      line_labels = rest.substr(1, close - 1);
      rest = rest.substr(close + 1);
    }
    if (rest.empty() || rest.front() != ' ') continue;  // a longer metric name with this prefix
    if (!labels.empty() && line_labels.find(labels) == std::string_view::npos) continue;
    while (!rest.empty() && rest.front() == ' ') rest.remove_prefix(1);
    const std::string value(rest.substr(0, rest.find(' ')));
    char* parse_end = nullptr;
    const double v = std::strtod(value.c_str(), &parse_end);
    if (parse_end == value.c_str()) continue;
    return v;
  }
  return std::nullopt;
}

RssSummary SummarizeRss(std::vector<RssSample> samples, double window_seconds) {
  RssSummary s;
  s.window_seconds = window_seconds;
  s.samples = std::move(samples);
  if (s.samples.empty()) return s;
  const double end = s.samples.back().seconds;
  for (const RssSample& r : s.samples) {
    s.peak = std::max(s.peak, r.bytes);
    if (r.seconds <= s.samples.front().seconds + window_seconds)
      s.first_window_max = std::max(s.first_window_max, r.bytes);
    if (r.seconds >= end - window_seconds) s.last_window_max = std::max(s.last_window_max, r.bytes);
  }
  if (s.first_window_max > 0)
    s.growth_percent = 100.0 *
                       (static_cast<double>(s.last_window_max) - static_cast<double>(s.first_window_max)) /
                       static_cast<double>(s.first_window_max);
  return s;
}

RssSampler::RssSampler(std::string url, std::chrono::milliseconds interval)
    : url_(std::move(url)), interval_(interval), start_(Clock::now()), thread_([this] { Loop(); }) {}

RssSampler::~RssSampler() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void RssSampler::SampleOnce() {
  const double t = std::chrono::duration<double>(Clock::now() - start_).count();
  std::optional<double> bytes;
  try {
    bytes = PrometheusSample(HttpGet(url_, std::chrono::seconds(5)), "process_resident_memory_bytes");
  } catch (const std::exception&) {
  }
  std::lock_guard lock(mutex_);
  if (bytes && *bytes >= 0)
    samples_.push_back({t, static_cast<std::uint64_t>(*bytes)});
  else
    ++failed_;
}

void RssSampler::Loop() {
  for (;;) {
    SampleOnce();
    std::unique_lock lock(mutex_);
    if (wake_.wait_for(lock, interval_, [this] { return stop_; })) return;
  }
}

RssSummary RssSampler::Stop() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
  SampleOnce();
  std::lock_guard lock(mutex_);
  RssSummary summary = SummarizeRss(samples_, 60.0);
  summary.url = url_;
  summary.interval_seconds = std::chrono::duration<double>(interval_).count();
  summary.failed_scrapes = failed_;
  return summary;
}

}  // namespace tubepick::cli
