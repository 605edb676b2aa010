# The cell controller end to end (unit tests of the state machine: clients/cell/test):
# - cell_e2e_test: a real in-process PlannerServer, the gRPC client and the simulated cell;
# - cell_cli_test: `tubepick cell --sim` starting tubepick-server itself (--server auto);
# - cell_devices_cli_test: `tubepick cell --devices` through the real drivers against `tubepick virtual-cell`.
if(TARGET tubepick_cli_cell)
  tubepick_add_test(cell_e2e_test SOURCES cell_e2e_test.cc LIBS tubepick_cli_cell tubepick_server)
  target_include_directories(cell_e2e_test PRIVATE ${PROJECT_SOURCE_DIR})
  if(TARGET tubepick-server)  # the planner as a process that can be killed (planner_outage.h)
    add_dependencies(cell_e2e_test tubepick-server)
    target_compile_definitions(cell_e2e_test PRIVATE TUBEPICK_SERVER="$<TARGET_FILE:tubepick-server>")
  endif()
endif()
if(TARGET tubepick-server)
  tubepick_add_test(cell_cli_test SOURCES cell_cli_test.cc LIBS nlohmann_json::nlohmann_json)
  target_include_directories(cell_cli_test PRIVATE ${PROJECT_SOURCE_DIR})
  add_dependencies(cell_cli_test tubepick tubepick-server)
  target_compile_definitions(cell_cli_test PRIVATE TUBEPICK_CLI="$<TARGET_FILE:tubepick>"
                                                   TUBEPICK_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  # `tubepick cell --devices` against `tubepick virtual-cell` (the real drivers, the real protocols),
  # `tubepick devices check`, and the operator's Ctrl-C.
  tubepick_add_test(cell_devices_cli_test SOURCES cell_devices_cli_test.cc LIBS nlohmann_json::nlohmann_json)
  target_include_directories(cell_devices_cli_test PRIVATE ${PROJECT_SOURCE_DIR})
  add_dependencies(cell_devices_cli_test tubepick tubepick-server)
  target_compile_definitions(cell_devices_cli_test PRIVATE TUBEPICK_CLI="$<TARGET_FILE:tubepick>"
                                                        TUBEPICK_SERVER="$<TARGET_FILE:tubepick-server>"
                                                        TUBEPICK_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
endif()
