# Compile settings every Skyshell target shares: warnings as errors for our own
# code, the sanitizer option, and the debug assert switch. Third-party headers
# are included as SYSTEM so their warnings do not fail our build.

add_library(sky_settings INTERFACE)
target_compile_options(sky_settings INTERFACE -Wall -Wextra -Werror)
if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
  # GCC 12 at -O3 reports std::string concatenation as overlapping memcpy
  # (-Wrestrict false positive, GCC bug 105329); it fails the Release build.
  target_compile_options(sky_settings INTERFACE -Wno-restrict)
endif()
# SKY_ASSERT stays active in every build of ours (tests and the demo run the
# RelWithDebInfo build, and a broken invariant must stop there, not render junk).
target_compile_definitions(sky_settings INTERFACE SKY_ENABLE_ASSERTS=1)
if(SKY_TSAN)
  # ThreadSanitizer (deploy/test --long): the processes of the integration
  # tests, built apart from the ASan tree since the two cannot be combined.
  # Asio's fenced blocks use std::atomic_thread_fence, which TSan does not
  # model (GCC refuses it under -Werror=tsan); its scheduler's mutex orders
  # the handlers anyway, and that TSan does see.
  target_compile_options(sky_settings INTERFACE -fsanitize=thread -fno-omit-frame-pointer)
  target_compile_definitions(sky_settings INTERFACE BOOST_ASIO_DISABLE_FENCED_BLOCK)
  target_link_options(sky_settings INTERFACE -fsanitize=thread)
elseif(SKY_SANITIZE)
  # Four of UBSan's checks are left out: vptr, alignment, null and
  # pointer-overflow instrument nearly every member call, load and pointer
  # step. In GCC they were 40 % of the tree's compile time (http_api.cpp: 56 s
  # with them, 32 s without; without UBSan 28 s). In deploy/test's clang tree
  # with them, its cold run took 2537 s (over the 40 minutes), and the vptr
  # check reported a false error in a process at its descriptor limit (it
  # reads the object through a pipe), which a hostile test makes on purpose.
  # AddressSanitizer still stops a null or out-of-bounds access, in the fuzz
  # targets too.
  target_compile_options(sky_settings INTERFACE
    -fsanitize=address,undefined -fno-sanitize=vptr,alignment,null,pointer-overflow
    -fno-sanitize-recover=undefined -fno-omit-frame-pointer)
  target_link_options(sky_settings INTERFACE -fsanitize=address,undefined)
endif()
# SKY_FUZZ (clang, with SKY_SANITIZE): libFuzzer's coverage instrumentation on
# every target, so the fuzz targets (tests/fuzz) link the same libraries as the
# other tests of the tree; outside a fuzz target the coverage hooks are the
# sanitizer runtime's empty defaults.
if(SKY_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang" OR NOT SKY_SANITIZE)
    message(FATAL_ERROR "SKY_FUZZ needs clang and SKY_SANITIZE: -DCMAKE_CXX_COMPILER=clang++-16 -DSKY_SANITIZE=ON")
  endif()
  target_compile_options(sky_settings INTERFACE -fsanitize=fuzzer-no-link)
endif()

# sky_add_library(name SOURCES ... DEPS ...): a library with a public include/
# next to its CMakeLists.txt and private sources.
function(sky_add_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(${name} STATIC ${ARG_SOURCES})
  target_include_directories(${name} PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/include)
  target_link_libraries(${name} PUBLIC sky_settings ${ARG_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
endfunction()

function(sky_add_executable name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE sky_settings ${ARG_DEPS})
endfunction()
