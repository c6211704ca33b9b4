# Copies the console's map libraries and data from npm (node_modules here,
# pinned by package-lock.json and installed by deploy/setup with npm ci) flat
# into the console's folder, each with its licence, for the server to serve
# (it serves one folder, no subfolders). Run at build time by
# server/CMakeLists.txt:
#   cmake -DVENDOR_DIR=<this folder> -DOUT_DIR=<console build folder> -P copy_vendor.cmake
# Stops the build, saying what to run, when the packages are missing or were
# installed from another lock file: a console without its map is not shipped.
cmake_minimum_required(VERSION 3.20)

# node_modules path -> the name the console serves it under.
set(files
  "leaflet/dist/leaflet.js=leaflet.js"
  "leaflet/dist/leaflet.css=leaflet.css"
  "leaflet/LICENSE=leaflet-LICENSE.txt"
  "topojson-client/dist/topojson-client.min.js=topojson-client.min.js"
  "topojson-client/LICENSE=topojson-client-LICENSE.txt"
  # Natural Earth 1:50m countries and land (public domain) as TopoJSON.
  "world-atlas/countries-50m.json=countries-50m.json"
  "world-atlas/LICENSE=world-atlas-LICENSE.txt")

set(modules "${VENDOR_DIR}/node_modules")
set(how "run deploy/setup, or: npm ci --prefix ${VENDOR_DIR} && cp ${VENDOR_DIR}/package-lock.json ${modules}/.skyshell-lock")
if(NOT EXISTS "${modules}/.skyshell-lock")
  message(FATAL_ERROR "The operator console's map packages (Leaflet, topojson-client, world-atlas) are not installed in ${modules}: ${how}")
endif()
file(READ "${VENDOR_DIR}/package-lock.json" wanted)
file(READ "${modules}/.skyshell-lock" installed)
if(NOT wanted STREQUAL installed)
  message(FATAL_ERROR "The console's map packages in ${modules} were installed from another package-lock.json: ${how}")
endif()
file(MAKE_DIRECTORY "${OUT_DIR}")
foreach(pair ${files})
  string(REPLACE "=" ";" pair "${pair}")
  list(GET pair 0 from)
  list(GET pair 1 to)
  if(NOT EXISTS "${modules}/${from}")
    message(FATAL_ERROR "The console's map packages lack ${from}: ${how}")
  endif()
  file(COPY_FILE "${modules}/${from}" "${OUT_DIR}/${to}" ONLY_IF_DIFFERENT)
endforeach()
