// The channel options every remote command takes, and the health answer's names.
#include "clients/cli/remote/channel.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "clients/cli/remote/health_command.h"
#include "core/common/errors.h"
#include "core/testing/error_of.h"

namespace tubepick::cli {
namespace {

using ::testing::HasSubstr;
using tubepick::testing::ErrorOf;

TEST(Channel, PlaintextByDefault) {
  ChannelOptions o;
  o.target = "127.0.0.1:1";
  EXPECT_NE(MakeChannel(o), nullptr);
}

TEST(Channel, TlsOptionMistakesNameTheOption) {
  ChannelOptions cert_only;
  cert_only.tls_cert_file = "client.pem";
  EXPECT_EQ(ErrorOf([&] { MakeChannel(cert_only); }), "--tls-cert and --tls-key: give both or neither");
  ChannelOptions name_only;
  name_only.tls_server_name = "planner.plant.local";
  EXPECT_EQ(ErrorOf([&] { MakeChannel(name_only); }), "--tls-server-name: needs --tls-ca");
  ChannelOptions missing_ca;
  missing_ca.tls_ca_file = "/nonexistent/ca.pem";
  EXPECT_THAT(ErrorOf([&] { MakeChannel(missing_ca); }),
              HasSubstr("--tls-ca: cannot read '/nonexistent/ca.pem'"));
}

TEST(Health, AClosedPortIsUnavailableNotServing) {
  ChannelOptions o;
  o.target = "127.0.0.1:1";
  const HealthAnswer a = CheckHealth(o, "", std::chrono::milliseconds(500));
  EXPECT_EQ(a.grpc_code, static_cast<int>(grpc::StatusCode::UNAVAILABLE));
  EXPECT_EQ(ToString(a.status), ToString(ServingStatus::kUnknown));
}

}  // namespace
}  // namespace tubepick::cli
