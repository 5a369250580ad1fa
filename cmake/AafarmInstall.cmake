# AafarmInstall.cmake: what `cmake --install` puts under a prefix, and the
# Debian package CPack makes of it (docs/building.md, "Installing"):
#   bin/                          the five programs
#   share/man/man1/aafarm-*.1     their manual pages, made from their --help
#   share/doc/aafarm/             README.md and docs/ (the guides)
#   share/aafarm/scenes/          the example scenes with their shaders
#   share/aafarm/deploy/          the ssh, Slurm and systemd launchers
# The programs need nothing else at run time: the standard shaders and
# lights are compiled in, and the master starts the aafarm-worker that sits
# beside it, so an installed tree works from any folder and any prefix.
include(GNUInstallDirs)

set(AAFARM_PROGRAMS aafarm-master aafarm-worker aafarm-slc aafarm-maketx aafarm-keygen aafarm-submit)
set(AAFARM_SUMMARY_aafarm-master "render a RenderMan scene on a farm of workers")
set(AAFARM_SUMMARY_aafarm-worker "render a RenderMan scene, alone or for a master")
set(AAFARM_SUMMARY_aafarm-slc    "check and compile RenderMan shading language shaders")
set(AAFARM_SUMMARY_aafarm-maketx "write tiled, mip-mapped OpenEXR textures")
set(AAFARM_SUMMARY_aafarm-keygen "write a CurveZMQ key pair for a master or a worker")
set(AAFARM_SUMMARY_aafarm-submit "submit, list and cancel jobs of a serving aafarm-master")

set(man_pages "")
foreach(prog IN LISTS AAFARM_PROGRAMS)
  if(NOT TARGET ${prog})
    message(FATAL_ERROR "AafarmInstall: target ${prog} is missing (are all dependencies found?)")
  endif()
  set(page ${CMAKE_BINARY_DIR}/man/${prog}.1)
  add_custom_command(
    OUTPUT ${page}
    COMMAND ${CMAKE_COMMAND} -DPROG=$<TARGET_FILE:${prog}> -DNAME=${prog}
            "-DSUMMARY=${AAFARM_SUMMARY_${prog}}" -DOUT=${page}
            -P ${PROJECT_SOURCE_DIR}/cmake/help2man.cmake
    DEPENDS ${prog} ${PROJECT_SOURCE_DIR}/cmake/help2man.cmake
    COMMENT "Manual page of ${prog}"
    VERBATIM)
  list(APPEND man_pages ${page})
endforeach()
add_custom_target(man ALL DEPENDS ${man_pages})

install(TARGETS ${AAFARM_PROGRAMS} RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(FILES ${man_pages} DESTINATION ${CMAKE_INSTALL_MANDIR}/man1)
install(FILES README.md DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(DIRECTORY docs/ DESTINATION ${CMAKE_INSTALL_DOCDIR}/docs)
install(DIRECTORY scenes/ DESTINATION ${CMAKE_INSTALL_DATADIR}/aafarm/scenes
        USE_SOURCE_PERMISSIONS
        PATTERN textures EXCLUDE)
foreach(dir ssh slurm systemd)
  install(DIRECTORY deploy/${dir} DESTINATION ${CMAKE_INSTALL_DATADIR}/aafarm/deploy
          USE_SOURCE_PERMISSIONS)
endforeach()

# ---- the Debian package: cpack -G DEB in the build folder ----
# aafarm_VERSION_ARCH.deb; Depends computed by dpkg-shlibdeps from the
# programs' shared libraries (libzmq5, libopenexr-3-1-30, ...).
set(CPACK_PACKAGE_NAME aafarm)
set(CPACK_PACKAGE_VENDOR "aafarm")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
    "render farm for procedural displacement shaders (affine arithmetic ray tracing)")
set(CPACK_PACKAGE_DESCRIPTION
    "aafarm renders RenderMan scenes with procedural displacement shaders, ray-traced
directly with affine arithmetic, on one host or on a farm of workers over
ZeroMQ with CurveZMQ. Programs: aafarm-master, aafarm-worker, aafarm-slc,
aafarm-maketx, aafarm-keygen; example scenes in /usr/share/aafarm/scenes.")
set(CPACK_PACKAGE_CONTACT "aafarm maintainers <aafarm@localhost>")
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_STRIP_FILES ON)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION graphics)
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)
find_program(AAFARM_DPKG_SHLIBDEPS dpkg-shlibdeps)
if(AAFARM_DPKG_SHLIBDEPS)
  set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
else()
  # no dpkg-shlibdeps (Debian package dpkg-dev): Debian 12's names, by hand
  set(CPACK_DEBIAN_PACKAGE_DEPENDS
      "libc6, libzmq5, libopenexr-3-1-30, libpng16-16, libtiff6, libprotobuf-c1, zlib1g, "
      "libmicrohttpd12, libsqlite3-0, libcurl4, libjson-c5")
endif()
include(CPack)
