# The gRPC service end to end: real PlannerServers in-process on loopback with real gRPC clients,
# plus the real tubepick-server binary as a child process (flags, JSON logs, SIGTERM). TLS material
# is generated at test time with the openssl CLI (tests/test_certs.sh) into a temporary directory.
tubepick_add_test(service_test
  SOURCES service_test_support.cc service_rpc_test.cc service_stream_test.cc service_ops_test.cc
          service_tls_test.cc service_process_test.cc service_parts_test.cc service_debug_test.cc
  LIBS tubepick_server tubepick_core_testing tubepick_physics gRPC::grpc++ protobuf::libprotobuf
       nlohmann_json::nlohmann_json spdlog::spdlog)
target_include_directories(service_test PRIVATE ${PROJECT_SOURCE_DIR})
add_dependencies(service_test tubepick-server)
target_compile_definitions(service_test PRIVATE TUBEPICK_SERVER_BIN="$<TARGET_FILE:tubepick-server>"
  TUBEPICK_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
