# Finds every third-party dependency (all from Debian's packages, installed by
# deploy/setup) and exposes each as an imported target with a sky:: name, so
# folders link by name and never spell include paths.

find_package(Threads REQUIRED)
find_package(PkgConfig REQUIRED)

pkg_check_modules(GEOGRAPHICLIB REQUIRED IMPORTED_TARGET geographiclib)
add_library(sky::geographiclib INTERFACE IMPORTED)
target_link_libraries(sky::geographiclib INTERFACE PkgConfig::GEOGRAPHICLIB)

# S2 geometry: Debian's libs2-dev has a CMake config (target s2::s2) on some
# versions only; fall back to the plain library.
find_package(s2 CONFIG QUIET)
add_library(sky::s2 INTERFACE IMPORTED)
if(TARGET s2::s2)
  target_link_libraries(sky::s2 INTERFACE s2::s2)
else()
  find_library(S2_LIBRARY NAMES s2 REQUIRED)
  find_path(S2_INCLUDE_DIR s2/s2cell_id.h REQUIRED)
  target_link_libraries(sky::s2 INTERFACE ${S2_LIBRARY})
  target_include_directories(sky::s2 SYSTEM INTERFACE ${S2_INCLUDE_DIR})
endif()

find_package(FlatBuffers CONFIG REQUIRED)
find_program(FLATC flatc REQUIRED)
add_library(sky::flatbuffers INTERFACE IMPORTED)
if(TARGET flatbuffers::flatbuffers_shared)
  target_link_libraries(sky::flatbuffers INTERFACE flatbuffers::flatbuffers_shared)
else()
  target_link_libraries(sky::flatbuffers INTERFACE flatbuffers::flatbuffers)
endif()

find_package(tl-expected CONFIG REQUIRED)
add_library(sky::expected INTERFACE IMPORTED)
target_link_libraries(sky::expected INTERFACE tl::expected)

find_package(Boost 1.74 REQUIRED)
add_library(sky::asio INTERFACE IMPORTED)
target_link_libraries(sky::asio INTERFACE Boost::headers Threads::Threads)
target_compile_definitions(sky::asio INTERFACE BOOST_ASIO_NO_DEPRECATED)

find_package(spdlog CONFIG REQUIRED)
add_library(sky::spdlog INTERFACE IMPORTED)
target_link_libraries(sky::spdlog INTERFACE spdlog::spdlog)

find_package(CLI11 CONFIG REQUIRED)
add_library(sky::cli11 INTERFACE IMPORTED)
target_link_libraries(sky::cli11 INTERFACE CLI11::CLI11)

pkg_check_modules(TOMLPLUSPLUS REQUIRED IMPORTED_TARGET tomlplusplus)
add_library(sky::toml INTERFACE IMPORTED)
target_link_libraries(sky::toml INTERFACE PkgConfig::TOMLPLUSPLUS)

find_package(nlohmann_json CONFIG REQUIRED)
add_library(sky::json INTERFACE IMPORTED)
target_link_libraries(sky::json INTERFACE nlohmann_json::nlohmann_json)

find_package(SQLite3 REQUIRED)
add_library(sky::sqlite INTERFACE IMPORTED)
target_link_libraries(sky::sqlite INTERFACE SQLite::SQLite3)

# GRIB2 forecasts (server/): Debian's libeccodes-dev. Its pkg-config file
# names an include directory relative to itself that does not exist (the
# header is under the multiarch include directory), so the library and the
# header are found directly.
find_library(ECCODES_LIBRARY NAMES eccodes REQUIRED)
find_path(ECCODES_INCLUDE_DIR eccodes.h PATH_SUFFIXES ${CMAKE_LIBRARY_ARCHITECTURE} REQUIRED)
add_library(sky::eccodes INTERFACE IMPORTED)
target_link_libraries(sky::eccodes INTERFACE ${ECCODES_LIBRARY})
target_include_directories(sky::eccodes SYSTEM INTERFACE ${ECCODES_INCLUDE_DIR})

# The weather on a NATS cluster (server/, skyshell-weatherd --nats): the C
# client nats.c, Debian's libnats-dev, found by its pkg-config file. Linked by
# the server library only; the renderer never sees it.
pkg_check_modules(LIBNATS REQUIRED IMPORTED_TARGET libnats)
add_library(sky::nats INTERFACE IMPORTED)
target_link_libraries(sky::nats INTERFACE PkgConfig::LIBNATS)

find_package(Vulkan REQUIRED)
find_program(GLSLANG_VALIDATOR glslangValidator REQUIRED)
find_program(SPIRV_OPT spirv-opt REQUIRED)
find_package(glm CONFIG REQUIRED)

find_path(STB_INCLUDE_DIR stb_image_write.h PATH_SUFFIXES stb REQUIRED)
add_library(sky::stb INTERFACE IMPORTED)
target_include_directories(sky::stb SYSTEM INTERFACE ${STB_INCLUDE_DIR})

# EXR frames (DESIGN.md: tinyexr or OpenEXR): Debian's libtinyexr-dev ships a
# compiled library with a CMake config (target tinyexr::tinyexr).
find_package(tinyexr CONFIG REQUIRED)
add_library(sky::tinyexr INTERFACE IMPORTED)
target_link_libraries(sky::tinyexr INTERFACE tinyexr::tinyexr)

# The windowed renderer's window (DESIGN.md: GLFW); libglfw3-dev's CMake
# config names the target glfw.
find_package(glfw3 CONFIG REQUIRED)
add_library(sky::glfw INTERFACE IMPORTED)
target_link_libraries(sky::glfw INTERFACE glfw)

if(SKY_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()

# GPX flight tracks are XML; expat is Debian's well-kept streaming XML parser
# (libexpat1-dev ships a CMake config with target expat::expat).
find_package(expat CONFIG REQUIRED)
add_library(sky::expat INTERFACE IMPORTED)
target_link_libraries(sky::expat INTERFACE expat::expat)

# Compressed flight files (readsb's gzip-compressed traces, KMZ's zip
# entries): zlib (zlib1g-dev), the reference deflate implementation; the zip
# container itself is a few fixed headers read by protocol/flight.
find_package(ZLIB REQUIRED)
add_library(sky::zlib INTERFACE IMPORTED)
target_link_libraries(sky::zlib INTERFACE ZLIB::ZLIB)
