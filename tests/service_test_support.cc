#include "tests/service_test_support.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <google/protobuf/descriptor.pb.h>
#include <grpcpp/generic/generic_stub.h>

#include <atomic>
#include <cstring>
#include <future>
#include <mutex>
#include <sstream>
#include <stdexcept>

#include "core/params.h"
#include "core/testing/synthetic_cloud.h"
#include "physics/scene_generator.h"
#include "physics/virtual_scanner.h"
#include "wire/packed_cloud.h"

namespace tubepick::service_test {
namespace {

// --- protobuf wire format, enough for grpc.health.v1 and grpc.reflection.v1alpha -------------

void AppendVarint(std::uint64_t v, std::string* out) {
  while (v >= 0x80) {
    out->push_back(static_cast<char>((v & 0x7f) | 0x80));
    v >>= 7;
  }
  out->push_back(static_cast<char>(v));
}

std::string StringField(int number, const std::string& value) {
  std::string out;
  AppendVarint(static_cast<std::uint64_t>(number) << 3 | 2, &out);
  AppendVarint(value.size(), &out);
  return out + value;
}

struct Field {
  int number = 0;
  std::uint64_t varint = 0;  // wire type 0
  std::string bytes;         // wire type 2
};

std::uint64_t ReadVarint(const std::string& in, std::size_t* pos) {
  std::uint64_t v = 0;
  for (int shift = 0; shift < 64; shift += 7) {
    if (*pos >= in.size()) throw std::runtime_error("truncated varint");
    const auto b = static_cast<std::uint8_t>(in[(*pos)++]);
    v |= static_cast<std::uint64_t>(b & 0x7f) << shift;
    if ((b & 0x80) == 0) return v;
  }
  throw std::runtime_error("varint too long");
}

std::vector<Field> ParseFields(const std::string& in) {
  std::vector<Field> fields;
  std::size_t pos = 0;
  while (pos < in.size()) {
    const std::uint64_t key = ReadVarint(in, &pos);
    Field f;
    f.number = static_cast<int>(key >> 3);
    switch (key & 7) {
      case 0:
        f.varint = ReadVarint(in, &pos);
        break;
      case 1:
        pos += 8;
        break;
      case 2: {
        const std::uint64_t len = ReadVarint(in, &pos);
        if (len > in.size() - pos) throw std::runtime_error("truncated field");
        f.bytes = in.substr(pos, len);
        pos += len;
        break;
      }
      case 5:
        pos += 4;
        break;
      default:
        throw std::runtime_error("unsupported wire type");
    }
    fields.push_back(std::move(f));
  }
  return fields;
}

// A generic bidi call: writes `requests`, half-closes, collects every response.
class Exchange final : public grpc::ClientBidiReactor<grpc::ByteBuffer, grpc::ByteBuffer> {
 public:
  Exchange(const std::shared_ptr<grpc::Channel>& channel, const std::string& method,
           std::vector<std::string> requests)
      : requests_(std::move(requests)) {
    SetTimeout(&context_, std::chrono::seconds(10));
    grpc::GenericStub stub(channel);
    stub.PrepareBidiStreamingCall(&context_, method, grpc::StubOptions(), this);
    StartRead(&in_);
    WriteNext();
    StartCall();
  }
  std::pair<grpc::Status, std::vector<std::string>> Wait() {
    grpc::Status status = done_.get_future().get();
    return {status, responses_};
  }

  void OnWriteDone(bool ok) override {
    if (ok) WriteNext();
  }
  void OnReadDone(bool ok) override {
    if (!ok) return;
    responses_.push_back(FromByteBuffer(in_));
    StartRead(&in_);
  }
  void OnDone(const grpc::Status& status) override { done_.set_value(status); }

 private:
  void WriteNext() {
    if (next_ < requests_.size()) {
      out_ = ToByteBuffer(requests_[next_++]);
      StartWrite(&out_);
    } else {
      StartWritesDone();
    }
  }

  grpc::ClientContext context_;
  std::vector<std::string> requests_;
  std::size_t next_ = 0;
  grpc::ByteBuffer out_, in_;
  std::vector<std::string> responses_;
  std::promise<grpc::Status> done_;
};

constexpr const char* kReflectionMethod = "/grpc.reflection.v1alpha.ServerReflection/ServerReflectionInfo";

std::vector<std::string> Reflect(const std::shared_ptr<grpc::Channel>& channel, const std::string& request) {
  Exchange exchange(channel, kReflectionMethod, {request});
  auto [status, responses] = exchange.Wait();
  if (!status.ok()) throw std::runtime_error("reflection: " + status.error_message());
  return responses;
}

}  // namespace

grpc::ByteBuffer ToByteBuffer(const std::string& bytes) {
  grpc::Slice slice(bytes);
  return grpc::ByteBuffer(&slice, 1);
}

std::string FromByteBuffer(const grpc::ByteBuffer& buffer) {
  std::vector<grpc::Slice> slices;
  if (!buffer.Dump(&slices).ok()) throw std::runtime_error("ByteBuffer::Dump failed");
  std::string out;
  for (const grpc::Slice& s : slices) out.append(reinterpret_cast<const char*>(s.begin()), s.size());
  return out;
}

std::string EncodeHealthCheckRequest(const std::string& service) {
  return service.empty() ? std::string() : StringField(1, service);
}

int DecodeServingStatus(const std::string& response) {
  int status = 0;  // UNKNOWN when absent
  for (const Field& f : ParseFields(response))
    if (f.number == 1) status = static_cast<int>(f.varint);
  return status;
}

server::ServerConfig TestConfig(std::uint32_t workers, std::uint32_t queue) {
  server::ServerConfig config;
  config.address = "127.0.0.1:0";
  config.metrics_address = "127.0.0.1:0";
  config.workers = workers;
  config.queue_capacity = queue;
  config.log_level = "warn";
  // "slow": the thesis profile without its random sampling, so every filter, the normals and the
  // segmentation run on the whole BusyBinCloud: a worker stays busy for seconds while polling its
  // StopToken as usual (cancellation, deadline and admission tests).
  Params slow = ProfileParams("thesis");
  for (FilterStep& step : slow.modeling.filters) {
    if (auto* sample = std::get_if<RandomSampleParams>(&step)) sample->count = 10'000'000;
  }
  config.planning.profiles["slow"] = slow;
  return config;
}

TestServer::TestServer(server::ServerConfig config) : config_(std::move(config)) {
  server_ = std::make_unique<server::PlannerServer>(config_);
  server_->Start();
  channel_ = grpc::CreateChannel(target(), grpc::InsecureChannelCredentials());
  stub_ = v1::PickPlannerService::NewStub(channel_);
}

TestServer::~TestServer() { server_->Shutdown(std::chrono::milliseconds(0)); }

std::string TestServer::target() const { return "127.0.0.1:" + std::to_string(server_->port()); }

std::unique_ptr<v1::PickPlannerService::Stub> TestServer::NewStub() const {
  // A distinct channel argument gives the channel its own subchannel, i.e. its own connection.
  static std::atomic<int> counter{0};
  grpc::ChannelArguments args;
  args.SetInt("tubepick.test.connection", ++counter);
  return v1::PickPlannerService::NewStub(
      grpc::CreateCustomChannel(target(), grpc::InsecureChannelCredentials(), args));
}

std::string PackCloud(const Points& points) { return PackXyz(points); }

const std::string& ThreeTubeCloud() {
  static const std::string cloud = [] {
    using tubepick::testing::FloorTube;
    tubepick::testing::SyntheticCloudParams params;
    params.floor = false;
    params.pixel_angle = 0.001;
    params.seed = 3;
    const auto rendered = tubepick::testing::RenderSyntheticCloud(
        {FloorTube({{-0.25, -0.18}, {0.25, -0.18}}), FloorTube({{-0.24, 0.0}, {0.24, 0.0}}),
         FloorTube({{-0.23, 0.18}, {0.23, 0.18}})},
        params);
    return PackCloud(rendered.points_Sensor);
  }();
  return cloud;
}

const std::string& EmptyBinCloud() {
  static const std::string cloud = [] {
    tubepick::testing::SyntheticCloudParams params;
    params.pixel_angle = 0.002;
    params.seed = 4;
    return PackCloud(tubepick::testing::RenderSyntheticCloud({}, params).points_Sensor);
  }();
  return cloud;
}

const std::string& BusyBinCloud() {
  static const std::string cloud = [] {
    const CellConfig cell;
    physics::SceneParams scene;
    scene.tube_count = 8;
    scene.bin = cell.bin;
    const physics::DropResult drop = physics::GenerateScene(scene, 21);
    physics::ScannerParams scanner;
    scanner.intrinsics = {960, 600, 800.0, 800.0, 479.5, 299.5};
    return PackCloud(physics::ScanScene(drop.tubes, cell, scanner, 21).points_Sensor);
  }();
  return cloud;
}

v1::ModelTubesRequest ModelRequest(const std::string& xyz) {
  v1::ModelTubesRequest request;
  request.mutable_cloud()->set_xyz(xyz);
  request.mutable_cloud()->set_unit(v1::LENGTH_UNIT_METRE);
  request.mutable_options()->set_seed(7);
  return request;
}

v1::PlanPickRequest PlanRequest(const std::string& xyz, bool simulate) {
  v1::PlanPickRequest request;
  request.mutable_cloud()->set_xyz(xyz);
  request.mutable_cloud()->set_unit(v1::LENGTH_UNIT_METRE);
  request.mutable_options()->set_seed(7);
  request.mutable_options()->set_disable_simulation(!simulate);
  return request;
}

v1::PlanPickRequest SlowPlanRequest() {
  v1::PlanPickRequest request = PlanRequest(BusyBinCloud(), true);
  request.mutable_options()->set_profile("slow");
  return request;
}

void SetTimeout(grpc::ClientContext* context, std::chrono::milliseconds timeout) {
  context->set_deadline(std::chrono::system_clock::now() + timeout);
}

HealthResult CheckHealth(const std::shared_ptr<grpc::Channel>& channel, const std::string& service) {
  grpc::GenericStub stub(channel);
  grpc::ClientContext context;
  SetTimeout(&context, std::chrono::seconds(5));
  const grpc::ByteBuffer request = ToByteBuffer(EncodeHealthCheckRequest(service));
  grpc::ByteBuffer response;
  std::promise<grpc::Status> done;
  stub.UnaryCall(&context, "/grpc.health.v1.Health/Check", grpc::StubOptions(), &request, &response,
                 [&](grpc::Status s) { done.set_value(std::move(s)); });
  HealthResult result;
  result.status = done.get_future().get();
  if (result.status.ok()) result.serving = DecodeServingStatus(FromByteBuffer(response));
  return result;
}

std::vector<std::string> ReflectionListServices(const std::shared_ptr<grpc::Channel>& channel) {
  std::vector<std::string> names;
  for (const std::string& response : Reflect(channel, StringField(7, "*"))) {
    for (const Field& f : ParseFields(response)) {
      if (f.number != 6) continue;  // list_services_response
      for (const Field& service : ParseFields(f.bytes))
        for (const Field& name : ParseFields(service.bytes))
          if (name.number == 1) names.push_back(name.bytes);
    }
  }
  return names;
}

std::vector<std::string> ReflectionDescribe(const std::shared_ptr<grpc::Channel>& channel,
                                            const std::string& symbol) {
  std::vector<std::string> out;
  for (const std::string& response : Reflect(channel, StringField(4, symbol))) {
    for (const Field& f : ParseFields(response)) {
      if (f.number != 4) continue;  // file_descriptor_response
      for (const Field& file : ParseFields(f.bytes)) {
        google::protobuf::FileDescriptorProto proto;
        if (file.number != 1 || !proto.ParseFromString(file.bytes)) continue;
        out.push_back(proto.name());
        for (const auto& service : proto.service())
          for (const auto& method : service.method()) out.push_back(service.name() + "." + method.name());
      }
    }
  }
  return out;
}

std::string HttpExchange(int port, const std::string& request) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) throw std::runtime_error("socket");
  timeval timeout{5, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<std::uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) {
    ::close(fd);
    throw std::runtime_error("connect to metrics port failed");
  }
  std::size_t sent = 0;
  while (sent < request.size()) {
    const ssize_t n = ::send(fd, request.data() + sent, request.size() - sent, MSG_NOSIGNAL);
    if (n <= 0) break;
    sent += static_cast<std::size_t>(n);
  }
  std::string answer;
  char buffer[4096];
  for (;;) {
    const ssize_t n = ::recv(fd, buffer, sizeof buffer, 0);
    if (n <= 0) break;
    answer.append(buffer, static_cast<std::size_t>(n));
  }
  ::close(fd);
  return answer;
}

std::string ScrapeMetrics(int port) {
  const std::string answer = HttpExchange(port, "GET /metrics HTTP/1.1\r\nHost: localhost\r\n\r\n");
  if (answer.rfind("HTTP/1.1 200 ", 0) != 0) throw std::runtime_error("metrics scrape failed: " + answer);
  const std::size_t body = answer.find("\r\n\r\n");
  return answer.substr(body + 4);
}

std::optional<double> MetricValue(const std::string& exposition, const std::string& series) {
  std::istringstream in(exposition);
  for (std::string line; std::getline(in, line);) {
    if (line.size() > series.size() && line.compare(0, series.size(), series) == 0 &&
        line[series.size()] == ' ')
      return std::stod(line.substr(series.size() + 1));
  }
  return std::nullopt;
}

}  // namespace tubepick::service_test
