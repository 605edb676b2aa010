# The load tool and the health check against a real PlannerServer in-process (tests/load_test.cc).
tubepick_add_test(load_test SOURCES load_test.cc LIBS tubepick_cli_load tubepick_server)
target_include_directories(load_test PRIVATE ${PROJECT_SOURCE_DIR})
