#include "clients/cli/remote/channel.h"

#include <fstream>
#include <sstream>

#include <grpcpp/create_channel.h>
#include <grpcpp/security/credentials.h>
#include <grpcpp/support/channel_arguments.h>

#include <fmt/core.h>

#include "core/common/errors.h"

namespace tubepick::cli {
namespace {

std::string ReadPem(const std::string& path, const std::string& option) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InvalidArgument(option + ": cannot read '" + path + "'");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace

void AddChannelOptions(CLI::App* cmd, ChannelOptions& o) {
  cmd->add_option("--target", o.target, "Server address HOST:PORT (or a gRPC target URI)")
      ->capture_default_str();
  cmd->add_option("--tls-ca", o.tls_ca_file, "PEM CA bundle for the server certificate (enables TLS)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--tls-cert", o.tls_cert_file, "PEM client certificate chain (mutual TLS)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--tls-key", o.tls_key_file, "PEM client private key (mutual TLS)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--tls-server-name", o.tls_server_name,
                  "Host name expected in the server certificate (default: the target's host)");
  cmd->add_option("--lb-policy", o.lb_policy, "gRPC load balancing over the target's addresses")
      ->check(CLI::IsMember({"pick_first", "round_robin"}));
}

std::shared_ptr<grpc::Channel> MakeChannel(const ChannelOptions& o) {
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(-1);
  args.SetMaxSendMessageSize(-1);
  if (!o.lb_policy.empty()) args.SetLoadBalancingPolicyName(o.lb_policy);

  const bool tls = !o.tls_ca_file.empty() || !o.tls_cert_file.empty();
  if (o.tls_cert_file.empty() != o.tls_key_file.empty())
    throw InvalidArgument("--tls-cert and --tls-key: give both or neither");
  if (!tls) {
    if (!o.tls_server_name.empty()) throw InvalidArgument("--tls-server-name: needs --tls-ca");
    return grpc::CreateCustomChannel(o.target, grpc::InsecureChannelCredentials(), args);
  }
  grpc::SslCredentialsOptions ssl;
  if (!o.tls_ca_file.empty()) ssl.pem_root_certs = ReadPem(o.tls_ca_file, "--tls-ca");
  if (!o.tls_cert_file.empty()) {
    ssl.pem_cert_chain = ReadPem(o.tls_cert_file, "--tls-cert");
    ssl.pem_private_key = ReadPem(o.tls_key_file, "--tls-key");
  }
  if (!o.tls_server_name.empty()) args.SetSslTargetNameOverride(o.tls_server_name);
  return grpc::CreateCustomChannel(o.target, grpc::SslCredentials(ssl), args);
}

}  // namespace tubepick::cli
