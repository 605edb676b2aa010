#include "server/http_endpoints.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <charconv>
#include <stdexcept>

#include "core/common/errors.h"
#include "server/debug_calls.h"

// Last: it includes <resolv.h>, whose `_res` macro would rewrite Eigen's parameters of that name.
#include <httplib.h>

namespace tubepick::server {
namespace {

constexpr const char* kPlain = "text/plain; charset=utf-8";

void Metrics(const HttpEndpointsOptions& o, httplib::Response& res) {
  res.set_content(o.render_metrics ? o.render_metrics() : std::string(),
                  "text/plain; version=0.0.4; charset=utf-8");
}

void Health(const HttpEndpointsOptions& o, httplib::Response& res) {
  const bool serving = o.serving();
  res.status = serving ? 200 : 503;
  res.set_content(serving ? "SERVING\n" : "NOT_SERVING\n", kPlain);
}

bool DebugOff(const HttpEndpointsOptions& o, httplib::Response& res) {
  if (o.debug_calls != nullptr) return false;
  res.status = 404;
  res.set_content(
      "the server keeps no calls: debug.keep_last is 0 (set it in the server config to see the last "
      "calls in the viewer)\n",
      kPlain);
  return true;
}

std::uint64_t CallId(const httplib::Request& req) {
  std::uint64_t id = 0;
  const std::string text = req.matches[1];
  std::from_chars(text.data(), text.data() + text.size(), id);
  return id;
}

void CallPage(const HttpEndpointsOptions& o, const httplib::Request& req, httplib::Response& res, bool json) {
  if (DebugOff(o, res)) return;
  const std::uint64_t id = CallId(req);
  const std::shared_ptr<const DebugCall> call = o.debug_calls->Find(id);
  if (!call) {
    res.status = 404;
    res.set_content(
        fmt::format("call {} is not kept (the server keeps its last calls: see /debug/calls)\n", id), kPlain);
    return;
  }
  const viewer::ViewPage page = o.debug_calls->PageOf(*call);
  if (json)
    res.set_content(viewer::PageDataJson(page), "application/json");
  else
    res.set_content(viewer::PageHtml(page), "text/html; charset=utf-8");
}

void Route(httplib::Server& http, const HttpEndpointsOptions& o) {
  http.Get("/metrics", [&o](const httplib::Request&, httplib::Response& res) { Metrics(o, res); });
  if (o.serving)
    http.Get("/healthz", [&o](const httplib::Request&, httplib::Response& res) { Health(o, res); });
  // Browsers ask for it on every page; "no content" keeps their consoles clean.
  http.Get("/favicon.ico", [](const httplib::Request&, httplib::Response& res) { res.status = 204; });
  http.Get("/debug/calls", [&o](const httplib::Request&, httplib::Response& res) {
    if (!DebugOff(o, res)) res.set_content(o.debug_calls->ListHtml(), "text/html; charset=utf-8");
  });
  http.Get("/debug/calls.json", [&o](const httplib::Request&, httplib::Response& res) {
    if (!DebugOff(o, res)) res.set_content(o.debug_calls->ListJson(), "application/json");
  });
  http.Get(R"(/debug/calls/(\d{1,19}))",
           [&o](const httplib::Request& req, httplib::Response& res) { CallPage(o, req, res, false); });
  http.Get(R"(/debug/calls/(\d{1,19})\.json)",
           [&o](const httplib::Request& req, httplib::Response& res) { CallPage(o, req, res, true); });
  // Only GET and HEAD are served; anything else is answered before routing.
  http.set_pre_routing_handler([](const httplib::Request& req, httplib::Response& res) {
    // Answers go uncompressed: the library would compress every text answer a client accepts
    // compressed, with Brotli at its slowest quality first (measured: 18.7 s of a core for one
    // 3.7 MB viewer page; gzip 0.4 s) — planning CPU spent on a debug page. The request object is the
    // library's own, not const; only the pre-routing hook sees it before the answer is written.
    const_cast<httplib::Request&>(req).headers.erase("Accept-Encoding");
    if (req.method == "GET" || req.method == "HEAD") return httplib::Server::HandlerResponse::Unhandled;
    res.status = 405;
    res.set_header("Allow", "GET, HEAD");
    res.set_content("only GET and HEAD\n", kPlain);
    return httplib::Server::HandlerResponse::Handled;
  });
  http.set_error_handler([](const httplib::Request& req, httplib::Response& res) {
    if (res.body.empty()) {
      res.set_content(fmt::format("HTTP {}{}\n", res.status, req.path.empty() ? "" : " for " + req.path),
                      kPlain);
    }
  });
  http.set_exception_handler([](const httplib::Request& req, httplib::Response& res, std::exception_ptr e) {
    std::string what = "unknown exception";
    try {
      if (e) std::rethrow_exception(e);
    } catch (const std::exception& ex) {
      what = ex.what();
    } catch (...) {
    }
    spdlog::error("http {} {}: {}", req.method, req.path, what);
    res.status = 500;
    res.set_content("internal error\n", kPlain);
  });
}

}  // namespace

std::pair<std::string, int> SplitHostPort(std::string_view address, const std::string& field) {
  const std::size_t colon = address.rfind(':');
  if (colon == std::string_view::npos || colon + 1 == address.size())
    throw InvalidArgument(fmt::format("{}: '{}' is not HOST:PORT", field, address));
  std::string_view host = address.substr(0, colon);
  const std::string_view port_text = address.substr(colon + 1);
  int port = -1;
  const auto [end, ec] = std::from_chars(port_text.data(), port_text.data() + port_text.size(), port);
  if (ec != std::errc() || end != port_text.data() + port_text.size() || port < 0 || port > 65535)
    throw InvalidArgument(fmt::format("{}: port '{}' of '{}' is not 0..65535", field, port_text, address));
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']') host = host.substr(1, host.size() - 2);
  return {std::string(host), port};
}

struct HttpEndpoints::Impl {
  explicit Impl(HttpEndpointsOptions o) : options(std::move(o)) {}
  HttpEndpointsOptions options;
  httplib::Server http;
};

HttpEndpoints::HttpEndpoints(const std::string& address, HttpEndpointsOptions options)
    : impl_(std::make_unique<Impl>(std::move(options))) {
  const auto [host, port] = SplitHostPort(address, "metrics_address");
  httplib::Server& http = impl_->http;
  const HttpEndpointsOptions& o = impl_->options;
  const int threads = std::max(1, o.threads);
  http.new_task_queue = [threads] { return new httplib::ThreadPool(static_cast<std::size_t>(threads)); };
  http.set_read_timeout(o.io_timeout);
  http.set_write_timeout(o.io_timeout);
  http.set_keep_alive_timeout(
      std::max<time_t>(1, std::chrono::duration_cast<std::chrono::seconds>(o.io_timeout).count()));
  http.set_payload_max_length(4096);
  http.set_keep_alive_max_count(1);
  // SO_REUSEADDR only: the library's default adds SO_REUSEPORT, with which a second server on a
  // busy port would share it silently instead of failing.
  http.set_socket_options([](socket_t sock) {
    int yes = 1;
    ::setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  });  // one request per connection: scrapes and probes are seconds apart
  Route(http, o);
  port_ = port == 0 ? http.bind_to_any_port(host) : (http.bind_to_port(host, port) ? port : -1);
  if (port_ <= 0) {
    throw std::runtime_error(
        fmt::format("metrics: cannot listen on {} (address in use or invalid?)", address));
  }
  thread_ = std::thread([this] { impl_->http.listen_after_bind(); });
  // stop() only takes effect once the server runs: wait for it (it starts at once after the bind).
  for (int i = 0; i < 2000 && !impl_->http.is_running(); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
}

HttpEndpoints::~HttpEndpoints() { Stop(); }

void HttpEndpoints::Stop() {
  if (!thread_.joinable()) return;
  impl_->http.stop();
  thread_.join();
}

}  // namespace tubepick::server
