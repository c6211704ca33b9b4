# Compile-time savings for the tree deploy/test builds cold (clang: ASan,
# UBSan and the fuzz targets), applied after every folder has defined
# its targets, so the folders' CMakeLists.txt stay as they are. Measured with
# /usr/bin/time on cold builds (user+sys CPU, the commit that added this file
# has the numbers).
#
# Boost.Asio and Boost.Beast separate compilation: header-only, each
# translation unit that includes them compiles their non-template parts
# (scheduler, reactor, socket operations, error categories, the HTTP parser,
# websocket framing) again; here they are compiled once, in sky_asio_beast
# (third_party/asio_beast/asio_beast.cpp), and every target linking sky::asio
# gets the two macros. They must be the same for every translation unit of a
# program that includes Asio or Beast, so they go on sky::asio (the only way
# our targets get Boost) and nowhere else.
add_library(sky_asio_beast STATIC ${PROJECT_SOURCE_DIR}/third_party/asio_beast/asio_beast.cpp)
# sky_settings: the tree's sanitizer and TSan options (BOOST_ASIO_DISABLE_FENCED_BLOCK)
# must be the same as for the code that calls it.
target_link_libraries(sky_asio_beast PUBLIC sky_settings Boost::headers Threads::Threads)
target_compile_definitions(sky_asio_beast PUBLIC
  BOOST_ASIO_NO_DEPRECATED BOOST_ASIO_SEPARATE_COMPILATION BOOST_BEAST_SEPARATE_COMPILATION)
target_link_libraries(sky::asio INTERFACE sky_asio_beast)

# Precompiled headers, clang only (the test tree): the standard library and,
# for the server library, Asio, Beast, nlohmann/json and spdlog, parsed once
# per target instead of once per file. Third-party and standard headers only:
# none of them depends on a macro our sources define before an include (those
# are stb's, GLFW's and our own SKY_* switches, none of them in these lists).
# With GCC 12 (the ASan and release trees) precompiled headers of these sets
# did not pay: loading the 100-350 MB .gch costs about what parsing saves.
set(SKY_PCH_STD <algorithm> <array> <charconv> <chrono> <cmath> <cstddef> <cstdint> <cstdio>
  <cstring> <functional> <limits> <map> <memory> <optional> <set> <span> <string>
  <string_view> <utility> <variant> <vector>)
set(SKY_PCH_ASIO ${SKY_PCH_STD} <atomic> <deque> <filesystem> <fstream> <mutex> <sstream>
  <thread> <unordered_map> <boost/asio.hpp> <boost/beast/core.hpp> <boost/beast/http.hpp>
  <boost/beast/websocket.hpp> <nlohmann/json.hpp>)
set(SKY_PCH_SERVER ${SKY_PCH_ASIO} <spdlog/spdlog.h>)
option(SKY_PCH "Precompiled headers for the heavy targets (clang builds)" ON)
# sky_precompile(SET TARGETS...): the headers of list variable SET,
# precompiled for each of the targets that exists in this tree.
function(sky_precompile set)
  foreach(target ${ARGN})
    if(TARGET ${target})
      target_precompile_headers(${target} PRIVATE ${${set}})
    endif()
  endforeach()
endfunction()
if(SKY_PCH AND CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
  sky_precompile(SKY_PCH_STD sky_protocol)
  sky_precompile(SKY_PCH_SERVER sky_server)
  # The programs of tests/ with several files, and the renderer's and sim
  # clients' libraries that include Asio: in the test tree the test programs
  # were 62 % of the compile time, most of it parsing gtest, the standard
  # library and (through server/ headers) Asio and Beast again in each file.
  # With these (and UBSan's four costly checks off, cmake/SkyTargets.cmake)
  # the tree's cold compile went from 2201 to 1513 CPU-s.
  # Asio and Beast only go into targets that link sky::asio (its separate
  # compilation macros must be on every file that includes them), spdlog
  # only into those that link sky::spdlog (its macros likewise).
  # A missing #include in a file of these targets does not show here; the
  # release tree (GCC, no precompiled headers) still catches it.
  set(SKY_PCH_TEST ${SKY_PCH_STD} <filesystem> <fstream> <sstream> <thread> <nlohmann/json.hpp>
    <gtest/gtest.h>)
  set(SKY_PCH_ASIO_TEST ${SKY_PCH_ASIO} <gtest/gtest.h>)
  set(SKY_PCH_SERVER_TEST ${SKY_PCH_SERVER} <gtest/gtest.h>)
  sky_precompile(SKY_PCH_SERVER_TEST sky_server_tests sky_grib_tests sky_server_http_tests
    sky_weatherd_nats_tests)
  sky_precompile(SKY_PCH_ASIO_TEST sky_integration_tests)
  sky_precompile(SKY_PCH_SERVER sky_render_app)
  sky_precompile(SKY_PCH_ASIO sky_sim)
  sky_precompile(SKY_PCH_TEST sky_protocol_tests sky_gpu_tests sky_cloud_types_tests
    sky_flight_tests sky_render_app_tests sky_cloud_core_tests sky_render_input_tests
    sky_sim_tests sky_presets_tests sky_bench_unit_tests sky_stability_tests)
endif()

# GCC's garbage collector: by default it collects whenever its heap grew by
# 100 % past 128 MB, which the Asio/Beast units (1-2 GB of allocations each)
# pay for with several collections (7 % of http_api.cpp's time). Collecting
# only past 1 GB trades memory for CPU: at most ~2 GB a compiler process,
# two at a time on the CI machine. Output and diagnostics are unchanged.
if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
  target_compile_options(sky_settings INTERFACE --param=ggc-min-expand=400 --param=ggc-min-heapsize=1048576)
endif()
