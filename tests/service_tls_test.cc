// TLS and mutual TLS of the gRPC port, with certificates made by tests/test_certs.sh (openssl CLI)
// into a temporary directory at test time.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "tests/service_test_support.h"

namespace tubepick::service_test {
namespace {

class ServiceTls : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    char pattern[] = "/tmp/tubepick-tls-XXXXXX";
    ASSERT_NE(::mkdtemp(pattern), nullptr);
    dir_ = pattern;
    const std::string command = std::string("sh ") + TUBEPICK_SOURCE_DIR "/tests/test_certs.sh " + dir_;
    ASSERT_EQ(std::system(command.c_str()), 0) << command;
  }
  static void TearDownTestSuite() { std::filesystem::remove_all(dir_); }

  static std::string Path(const std::string& name) { return dir_ + "/" + name; }
  static std::string Read(const std::string& name) {
    std::ifstream in(Path(name));
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
  }

  static server::ServerConfig TlsConfig(bool mutual) {
    server::ServerConfig config = TestConfig(1, 4);
    config.tls.cert_file = Path("server.pem");
    config.tls.key_file = Path("server.key");
    if (mutual) {
      config.tls.client_ca_file = Path("ca.pem");
      config.tls.require_client_cert = true;
    }
    return config;
  }

  /// ModelTubes over a TLS channel trusting `ca`, presenting `client` (name of a .pem/.key pair) if
  /// not empty.
  static grpc::Status CallOverTls(const TestServer& server, const std::string& ca, const std::string& client,
                                  int* tubes = nullptr) {
    grpc::SslCredentialsOptions options;
    options.pem_root_certs = Read(ca);
    if (!client.empty()) {
      options.pem_cert_chain = Read(client + ".pem");
      options.pem_private_key = Read(client + ".key");
    }
    return Call(grpc::CreateChannel(server.target(), grpc::SslCredentials(options)), tubes);
  }

  static grpc::Status Call(const std::shared_ptr<grpc::Channel>& channel, int* tubes = nullptr) {
    auto stub = v1::PickPlannerService::NewStub(channel);
    grpc::ClientContext context;
    SetTimeout(&context, std::chrono::seconds(20));
    v1::ModelTubesResponse response;
    const grpc::Status status = stub->ModelTubes(&context, ModelRequest(ThreeTubeCloud()), &response);
    if (tubes) *tubes = response.tubes_size();
    return status;
  }

  static std::string dir_;
};

std::string ServiceTls::dir_;

TEST_F(ServiceTls, ServesClientsThatTrustItsCaAndNothingElse) {
  TestServer server(TlsConfig(false));
  int tubes = 0;
  const grpc::Status ok = CallOverTls(server, "ca.pem", "", &tubes);
  ASSERT_TRUE(ok.ok()) << ok.error_message();
  EXPECT_EQ(tubes, 3);
  // A plaintext client and a client trusting another CA never get an answer.
  EXPECT_EQ(Call(server.channel()).error_code(), grpc::StatusCode::UNAVAILABLE);
  EXPECT_EQ(CallOverTls(server, "other-ca.pem", "").error_code(), grpc::StatusCode::UNAVAILABLE);
}

TEST_F(ServiceTls, MutualTlsRequiresAClientCertificateFromTheClientCa) {
  TestServer server(TlsConfig(true));
  int tubes = 0;
  const grpc::Status ok = CallOverTls(server, "ca.pem", "client", &tubes);
  ASSERT_TRUE(ok.ok()) << ok.error_message();
  EXPECT_EQ(tubes, 3);
  EXPECT_EQ(CallOverTls(server, "ca.pem", "").error_code(), grpc::StatusCode::UNAVAILABLE)
      << "a client without a certificate must be rejected";
  EXPECT_EQ(CallOverTls(server, "ca.pem", "other-client").error_code(), grpc::StatusCode::UNAVAILABLE)
      << "a certificate from another CA must be rejected";
}

TEST_F(ServiceTls, AnUnreadableCertificateFailsAtConstruction) {
  server::ServerConfig config = TlsConfig(false);
  config.tls.cert_file = Path("missing.pem");
  EXPECT_ANY_THROW(server::PlannerServer server(config));
}

}  // namespace
}  // namespace tubepick::service_test
