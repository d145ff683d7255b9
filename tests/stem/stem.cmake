# The stem measurement (pipeline/stem) on hand-computed quadrangles and on rendered cylinders.
fieldrig_add_test(stem_quadrangle_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/stem_quadrangle_test.cpp
                  LIBS fieldrig::stem LABELS stem)
fieldrig_add_test(stem_log_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/stem_log_test.cpp
                  LIBS fieldrig::stem LABELS stem)
fieldrig_add_test(stem_measure_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/stem_measure_test.cpp
                  LIBS fieldrig::stem fieldrig::sim_render LABELS stem)

# The stem page (tools/stem_page): its route table, and its API on a recorded session, without a
# server.
fieldrig_add_test(stem_page_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/stem_page_routes_test.cpp
                                         ${CMAKE_CURRENT_LIST_DIR}/stem_page_test.cpp
                  LIBS fieldrig::stem_page LABELS stem tools)

# `fieldrig stem`: the command's contract, run as the built binary on rendered pairs.
fieldrig_add_test(stem_cli_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/stem_cli_test.cpp
                  LIBS fieldrig::stem fieldrig::sim_render nlohmann_json::nlohmann_json
                  LABELS stem tools)
add_dependencies(stem_cli_test fieldrig)

# `fieldrig stem-ui` in real headless Chromium, driven by Playwright (playwright-core from npm,
# pinned in browser/package-lock.json). The fixture installs it with `npm ci` into the build
# folder (network: registry.npmjs.org); without /usr/bin/chromium both skip.
set(stem_browser_dir ${CMAKE_CURRENT_BINARY_DIR}/browser)
foreach(file package.json package-lock.json stem_ui_browser.cjs)
  configure_file(${CMAKE_CURRENT_LIST_DIR}/browser/${file} ${stem_browser_dir}/${file} COPYONLY)
endforeach()
add_test(NAME stem_browser_npm_ci
         COMMAND sh -c "if [ ! -x /usr/bin/chromium ]; then echo 'no /usr/bin/chromium: skipped'; exit 0; fi; npm ci --no-audit --no-fund"
         WORKING_DIRECTORY ${stem_browser_dir})
set_tests_properties(stem_browser_npm_ci PROPERTIES FIXTURES_SETUP stem_browser LABELS "stem"
                     SKIP_REGULAR_EXPRESSION "skipped")
# Registered as one CTest test (not per GoogleTest case) so that it can require the fixture.
add_executable(stem_ui_browser_test ${CMAKE_CURRENT_LIST_DIR}/stem_ui_browser_test.cpp)
target_link_libraries(stem_ui_browser_test PRIVATE fieldrig::stem fieldrig::sim_render
                      fieldrig::recording nlohmann_json::nlohmann_json GTest::gtest GTest::gtest_main)
target_include_directories(stem_ui_browser_test PRIVATE ${PROJECT_SOURCE_DIR}/tests)
target_compile_definitions(stem_ui_browser_test PRIVATE
  FIELDRIG_BINARY_DIR="${PROJECT_BINARY_DIR}" STEM_BROWSER_DIR="${stem_browser_dir}")
add_dependencies(stem_ui_browser_test fieldrig)
add_test(NAME stem_ui_browser_test COMMAND stem_ui_browser_test)
set_tests_properties(stem_ui_browser_test PROPERTIES FIXTURES_REQUIRED stem_browser
                     LABELS "stem;tools;browser" SKIP_REGULAR_EXPRESSION "\\[  SKIPPED \\]"
                     TIMEOUT 180)
