#pragma once

#include <memory>
#include <string>

#include <grpcpp/security/credentials.h>
#include <grpcpp/support/channel_arguments.h>

namespace tubepick::cell {

/// The TLS files of a gRPC client: the same PEM files the server's `tls` section names (its
/// cert_file / key_file / client_ca_file), seen from the client.
struct ClientTlsFiles {
  /// PEM CA bundle the server certificate must chain to.
  std::string ca_file;
  /// PEM client certificate chain and its private key, for a server that requires mutual TLS.
  std::string cert_file;
  std::string key_file;
  /// Host name checked against the server certificate instead of the target's host (SNI / SAN).
  std::string server_name;

  /// TLS is on when a CA or a client certificate is given.
  bool tls() const { return !ca_file.empty() || !cert_file.empty(); }
};

/// How the caller's options are spelled in error messages: the cell controller's
/// GrpcPlannerClientOptions fields by default, a CLI would pass its flags ("--tls-ca", ...).
struct ClientTlsOptionNames {
  std::string ca_file = "tls_ca_file";
  std::string cert_file = "tls_cert_file";
  std::string key_file = "tls_key_file";
  std::string server_name = "tls_server_name";
};

/// Channel credentials for `files`: insecure (plaintext) when none is given, else TLS, mutual when
/// a client certificate is given (without a CA the system's roots verify the server). Sets the
/// SSL target name override on `args` when server_name is given.
/// @throws InvalidArgument naming the options when they are inconsistent (a certificate without
///   its key or a key without its certificate, a server name without a CA), or naming the file
///   when one cannot be read or holds no PEM block.
std::shared_ptr<grpc::ChannelCredentials> MakeClientCredentials(const ClientTlsFiles& files,
                                                                grpc::ChannelArguments& args,
                                                                const ClientTlsOptionNames& names = {});

}  // namespace tubepick::cell
