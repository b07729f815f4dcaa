# Installing evldt on a robot: where `cmake --install` puts things, and the Debian package made from
# the same rules (`cpack -G DEB` in a build configured with CMAKE_INSTALL_PREFIX=/usr, as
# deploy/make-deb.sh does). Binaries go to bin/ (each target's own install rule), the lcm-spy jar to
# share/java, the media module to lib/<arch>/evldt; here: the sensor configurations and the units'
# environment files to <sysconfdir>/evldt (/etc/evldt for /usr), the systemd units to
# lib/systemd/system with the paths of this prefix.
include(GNUInstallDirs)
set(EVLDT_SYSCONF_DIR ${CMAKE_INSTALL_FULL_SYSCONFDIR}/evldt)

install(DIRECTORY config/ DESTINATION ${EVLDT_SYSCONF_DIR} FILES_MATCHING PATTERN "*.toml")

# deploy/systemd holds the units as a hand install places them (/usr/local/bin, /etc/evldt);
# installed ones name this prefix's folders.
file(GLOB evldt_deploy_files LIST_DIRECTORIES false ${PROJECT_SOURCE_DIR}/deploy/systemd/*)
set(evldt_units_dir ${CMAKE_CURRENT_BINARY_DIR}/systemd)
foreach(source ${evldt_deploy_files})
  get_filename_component(name ${source} NAME)
  file(READ ${source} text)
  string(REPLACE "/usr/local/bin/" "${CMAKE_INSTALL_FULL_BINDIR}/" text "${text}")
  string(REPLACE "/etc/evldt/" "${EVLDT_SYSCONF_DIR}/" text "${text}")
  file(WRITE ${evldt_units_dir}/${name} "${text}")
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${source})
  if(name MATCHES "\\.service$")
    install(FILES ${evldt_units_dir}/${name} DESTINATION lib/systemd/system)
  else()
    install(FILES ${evldt_units_dir}/${name} DESTINATION ${EVLDT_SYSCONF_DIR})
  endif()
endforeach()

# For programs of one's own (issue 51): a CMake package (find_package(evldt): evldt::lcmtypes,
# evldt::client) and a pkg-config file, both relocatable (paths relative to where they lie).
include(CMakePackageConfigHelpers)
set(evldt_cmake_dir ${CMAKE_INSTALL_LIBDIR}/cmake/evldt)
file(RELATIVE_PATH EVLDT_CONFIG_TO_PREFIX ${CMAKE_INSTALL_PREFIX}/${evldt_cmake_dir} ${CMAKE_INSTALL_PREFIX})
configure_file(${PROJECT_SOURCE_DIR}/cmake/evldtConfig.cmake.in ${CMAKE_CURRENT_BINARY_DIR}/evldtConfig.cmake @ONLY)
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/evldtConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/evldtConfig.cmake ${CMAKE_CURRENT_BINARY_DIR}/evldtConfigVersion.cmake
        DESTINATION ${evldt_cmake_dir})
file(RELATIVE_PATH EVLDT_PC_TO_PREFIX ${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_LIBDIR}/pkgconfig ${CMAKE_INSTALL_PREFIX})
configure_file(${PROJECT_SOURCE_DIR}/cmake/evldt.pc.in ${CMAKE_CURRENT_BINARY_DIR}/evldt.pc @ONLY)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/evldt.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)

# Sources of live cameras (a RAW stream over TCP, a followed RAW file, DV's and cAER's network
# output), to copy to <sysconfdir>/evldt/camera-NAME.env.
install(DIRECTORY ${PROJECT_SOURCE_DIR}/deploy/systemd/examples/ DESTINATION ${CMAKE_INSTALL_DOCDIR}/examples)

# The Debian package: every install rule but the Python module's (built for the Python that
# configured the build, not Debian's). Its library dependencies come from dpkg-shlibdeps; the
# logger unit needs lcm-logger, lcm-spy (deploy/lcm-spy.sh) a Java runtime.
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME evldt)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_CONTACT "evldt developers <evldt@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "real-time line-segment detection and tracking from an event camera, as LCM services")
set(CPACK_PACKAGE_DESCRIPTION "evldt detects and tracks line segments in the events of an event camera alone (SCARF lattice,
 fitting-score detection, endpoint-perturbation tracking). The services (camera ingestion, lines,
 viz) talk over LCM multicast; the tools read recordings, simulate scenes and score the lines.")
set(CPACK_INSTALL_CMAKE_PROJECTS "${CMAKE_BINARY_DIR};evldt;Unspecified;/")  # the rules of no named component
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_DEPENDS "liblcm-bin")  # lcm-logger; building against the SDK needs liblcm-dev too
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "liblcm-dev")  # to build against the SDK
set(CPACK_DEBIAN_PACKAGE_SUGGESTS "liblcm-java, default-jre-headless, libjchart2d-java")
# What a robot's administrator edits stays theirs across upgrades.
set(evldt_conffiles ${CMAKE_CURRENT_BINARY_DIR}/debian/conffiles)
file(GLOB evldt_configs RELATIVE ${PROJECT_SOURCE_DIR}/config ${PROJECT_SOURCE_DIR}/config/*.toml)
set(conffiles_text "")
foreach(name ${evldt_configs} evldt.env camera-cam0.env)
  string(APPEND conffiles_text "${EVLDT_SYSCONF_DIR}/${name}\n")
endforeach()
file(WRITE ${evldt_conffiles} "${conffiles_text}")
set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA ${evldt_conffiles})
include(CPack)
