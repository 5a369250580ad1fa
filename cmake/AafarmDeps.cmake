# cmake/AafarmDeps.cmake: find aafarm's external libraries. Every missing
# dependency stops configuration with the Debian package that provides it
# (deploy/install-deps.sh installs them all).
find_package(PkgConfig)
if(NOT PKG_CONFIG_FOUND)
  message(FATAL_ERROR "pkg-config not found: install the Debian package 'pkg-config' "
                      "(or run deploy/install-deps.sh as root)")
endif()

function(aafarm_require_pkgconfig prefix module debian_pkg)
  pkg_check_modules(${prefix} QUIET IMPORTED_TARGET GLOBAL ${module})
  if(NOT ${prefix}_FOUND)
    message(FATAL_ERROR "${module} not found (pkg-config module '${module}'): "
                        "install the Debian package '${debian_pkg}' "
                        "(or run deploy/install-deps.sh as root)")
  endif()
  message(STATUS "Found ${module} ${${prefix}_VERSION}")
endfunction()

aafarm_require_pkgconfig(ZMQ libzmq libzmq3-dev)
aafarm_require_pkgconfig(PNG libpng libpng-dev)
aafarm_require_pkgconfig(ZLIB zlib zlib1g-dev)
aafarm_require_pkgconfig(TIFF libtiff-4 libtiff-dev)
aafarm_require_pkgconfig(MHD libmicrohttpd libmicrohttpd-dev)   # the master's live monitor
aafarm_require_pkgconfig(SQLITE sqlite3 libsqlite3-dev)          # the master's job queue (--serve)
aafarm_require_pkgconfig(CURL libcurl libcurl4-openssl-dev)      # aafarm-submit (and tests)
aafarm_require_pkgconfig(JSONC json-c libjson-c-dev)             # aafarm-submit's answers (and tests)

find_package(OpenEXR 3 CONFIG QUIET)
if(NOT OpenEXR_FOUND OR NOT TARGET OpenEXR::OpenEXRCore)
  message(FATAL_ERROR "OpenEXR 3 (CMake package OpenEXR, target OpenEXR::OpenEXRCore) "
                      "not found: install the Debian package 'libopenexr-dev' "
                      "(or run deploy/install-deps.sh as root)")
endif()
message(STATUS "Found OpenEXR ${OpenEXR_VERSION} (OpenEXRCore)")

if(AAFARM_TESTS)
  aafarm_require_pkgconfig(CMOCKA cmocka libcmocka-dev)
endif()

find_library(MATH_LIBRARY m REQUIRED)
