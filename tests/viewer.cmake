# The 3-D viewer in a real browser (tests/viewer_browser.sh): pages of `tubepick view`, of a cell
# round (--view) and of a running server's /debug/calls, in Debian's headless chromium driven by
# playwright-core (viewer/package-lock.json). Screenshots: build/artifacts/viewer/.
if(TARGET tubepick-server)
  add_test(NAME viewer_browser
    COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/viewer_browser.sh $<TARGET_FILE:tubepick-server> $<TARGET_FILE:tubepick>
            ${PROJECT_BINARY_DIR}/artifacts/viewer)
  # COST: the longest test (about 80 s) starts first, beside the short ones, even without timings of a
  # previous run (a fresh CI machine); numbered last, it would otherwise run alone at the end.
  set_tests_properties(viewer_browser PROPERTIES TIMEOUT 900 COST 1000)
endif()
