#include "clients/cell/client_credentials.h"

#include <fmt/core.h>

#include <fstream>
#include <sstream>

#include "core/common/errors.h"

namespace tubepick::cell {
namespace {

/// The file's text; it must hold a PEM block ("-----BEGIN ...").
std::string ReadPem(const std::string& path, const std::string& option) {
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw InvalidArgument(
        fmt::format("{} '{}': cannot read the file (wrong path, permissions?)", option, path));
  std::ostringstream text;
  text << in.rdbuf();
  if (text.str().find("-----BEGIN ") == std::string::npos)
    throw InvalidArgument(fmt::format(
        "{} '{}': no PEM block (-----BEGIN ...) in the file (a DER file, or the wrong file?)", option, path));
  return text.str();
}

}  // namespace

std::shared_ptr<grpc::ChannelCredentials> MakeClientCredentials(const ClientTlsFiles& files,
                                                                grpc::ChannelArguments& args,
                                                                const ClientTlsOptionNames& names) {
  if (!files.cert_file.empty() && files.key_file.empty())
    throw InvalidArgument(
        fmt::format("{} '{}' is set without {}: mutual TLS needs the certificate's private key too",
                    names.cert_file, files.cert_file, names.key_file));
  if (files.cert_file.empty() && !files.key_file.empty())
    throw InvalidArgument(
        fmt::format("{} '{}' is set without {}: mutual TLS needs the client certificate too", names.key_file,
                    files.key_file, names.cert_file));
  if (!files.server_name.empty() && files.ca_file.empty())
    throw InvalidArgument(fmt::format(
        "{} '{}' is set without {}: the server name is checked against a certificate verified by that CA "
        "(set {} to the CA that signed the planner's certificate)",
        names.server_name, files.server_name, names.ca_file, names.ca_file));
  if (!files.tls()) return grpc::InsecureChannelCredentials();

  grpc::SslCredentialsOptions ssl;
  if (!files.ca_file.empty()) ssl.pem_root_certs = ReadPem(files.ca_file, names.ca_file);
  if (!files.cert_file.empty()) {
    ssl.pem_cert_chain = ReadPem(files.cert_file, names.cert_file);
    ssl.pem_private_key = ReadPem(files.key_file, names.key_file);
  }
  if (!files.server_name.empty()) args.SetSslTargetNameOverride(files.server_name);
  return grpc::SslCredentials(ssl);
}

}  // namespace tubepick::cell
