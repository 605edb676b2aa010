# Shell-level checks run by ctest (hence by CI's deploy/test.sh): the proto lint and breaking-change
# check with the pinned buf, and the smoke test of the real tubepick-server binary driven by buf curl
# and the tubepick CLI.
add_test(NAME proto_lint COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/proto_lint.sh)
set_tests_properties(proto_lint PROPERTIES TIMEOUT 120)
# buf breaking of proto/ against HEAD~1 and a fixed baseline commit of the git history (see the script).
add_test(NAME proto_breaking COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/proto_breaking.sh)
set_tests_properties(proto_breaking PROPERTIES TIMEOUT 120)

if(TARGET tubepick-server)
  add_test(NAME smoke
    COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/smoke.sh $<TARGET_FILE:tubepick-server> $<TARGET_FILE:tubepick>)
  # Binds only 127.0.0.1:0 ports, so it may run beside other tests.
  set_tests_properties(smoke PROPERTIES TIMEOUT 600 COST 100)  # started early (see viewer.cmake)
endif()
