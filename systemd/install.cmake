# Install rules of the executables, include()d from the top-level CMakeLists.txt after every
# add_subdirectory(): install(TARGETS) needs the targets to exist. The unit in systemd/ runs
# ${CMAKE_INSTALL_FULL_BINDIR}/fieldrigd, which is where this puts it.
include(GNUInstallDirs)
# fieldrig is a launcher; the programs it runs go to libexec/fieldrig (tools/CMakeLists.txt).
install(TARGETS fieldrig-commands fieldrig-traits RUNTIME DESTINATION ${CMAKE_INSTALL_LIBEXECDIR}/fieldrig)
if(TARGET fieldrigd)
  install(TARGETS fieldrig fieldrigd RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  # Read by the systemd.install test (systemd/CMakeLists.txt): it then checks both executables.
  set_property(TARGET fieldrigd PROPERTY FIELDRIG_INSTALLED ON)
elseif(TARGET fieldrig)
  install(TARGETS fieldrig RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()
