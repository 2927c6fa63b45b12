# Run by `cmake --install` (install(SCRIPT)): installs the example configuration as
# <sysconfdir>/hpose/hposed.yaml and the systemd unit <prefix>/lib/systemd/system/hposed.service
# with the paths of this installation. It runs at install time, so `cmake --install --prefix P`
# (and CPack's staging) get paths under P. Expects HPOSE_SOURCE_DIR, HPOSE_BINARY_DIR and the
# configured CMAKE_INSTALL_{BINDIR,SYSCONFDIR,DOCDIR} (HPOSE_CONF_*), set by the caller.

# GNUInstallDirs' rule for the configuration directory: an absolute SYSCONFDIR as is; the
# /usr prefix uses /etc; any other prefix its own etc/.
if(IS_ABSOLUTE "${HPOSE_CONF_SYSCONFDIR}")
  set(_etc "${HPOSE_CONF_SYSCONFDIR}")
elseif(CMAKE_INSTALL_PREFIX STREQUAL "/usr")
  set(_etc "/${HPOSE_CONF_SYSCONFDIR}")
else()
  set(_etc "${CMAKE_INSTALL_PREFIX}/${HPOSE_CONF_SYSCONFDIR}")
endif()

set(HPOSE_BIN_DIR "${CMAKE_INSTALL_PREFIX}/${HPOSE_CONF_BINDIR}")
set(HPOSE_DOC_DIR "${CMAKE_INSTALL_PREFIX}/${HPOSE_CONF_DOCDIR}")
set(HPOSE_CONFIG_FILE "${_etc}/hpose/hposed.yaml")

file(MAKE_DIRECTORY "${HPOSE_BINARY_DIR}/packaging")
file(COPY_FILE "${HPOSE_SOURCE_DIR}/server/hposed.example.yaml"
     "${HPOSE_BINARY_DIR}/packaging/hposed.yaml")
configure_file("${HPOSE_SOURCE_DIR}/packaging/hposed.service.in"
               "${HPOSE_BINARY_DIR}/packaging/hposed.service" @ONLY)

# An existing configuration is the user's: it is kept (the .deb marks it a conffile, so dpkg
# asks before replacing an edited one).
if(EXISTS "$ENV{DESTDIR}${HPOSE_CONFIG_FILE}")
  message(STATUS "Keeping: $ENV{DESTDIR}${HPOSE_CONFIG_FILE} (the example is "
                 "${HPOSE_SOURCE_DIR}/server/hposed.example.yaml)")
else()
  file(INSTALL "${HPOSE_BINARY_DIR}/packaging/hposed.yaml" DESTINATION "${_etc}/hpose"
       PERMISSIONS OWNER_READ OWNER_WRITE GROUP_READ WORLD_READ)
endif()
file(INSTALL "${HPOSE_BINARY_DIR}/packaging/hposed.service"
     DESTINATION "${CMAKE_INSTALL_PREFIX}/lib/systemd/system"
     PERMISSIONS OWNER_READ OWNER_WRITE GROUP_READ WORLD_READ)
