# What `cmake --install build --prefix P` puts in P (docs/INSTALL.md):
#   lib/            libtumble_physics.a; with the service: libtumble_client.a, libtumble_proto.a,
#                   libtumble_recording_writer.a
#   include/tumble/ physics/*.h (the engine), v1/*.pb.h (the API), client.h and its neighbours
#   lib/cmake/Tumble/  find_package(Tumble): tumble::physics, tumble::client
#   lib/pkgconfig/  tumble.pc (the engine), tumble-client.pc
#   bin/            the programs this build made; share/tumble/ shaders, protos and scenes
include(CMakePackageConfigHelpers)
set(tumble_cmake_dir ${CMAKE_INSTALL_LIBDIR}/cmake/Tumble)

install(TARGETS tumble_physics EXPORT TumblePhysicsTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(DIRECTORY physics/include/physics DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/tumble)
install(EXPORT TumblePhysicsTargets NAMESPACE tumble:: DESTINATION ${tumble_cmake_dir})

set(TUMBLE_INSTALLS_CLIENT ${TUMBLE_BUILD_SERVER})
if(TUMBLE_INSTALLS_CLIENT)
  install(TARGETS tumble_client tumble_proto tumble_recording_writer EXPORT TumbleClientTargets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
  install(FILES client/client.h client/recording.h client/frame_format.h
    proto/tumble/recording_writer.h proto/tumble/mcap.h proto/tumble/wire_status.h
    DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/tumble)
  foreach(proto world snapshot recording)
    install(FILES ${PROJECT_BINARY_DIR}/proto/tumble/v1/${proto}.pb.h
                  ${PROJECT_BINARY_DIR}/proto/tumble/v1/${proto}.grpc.pb.h
            DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/tumble/v1)
  endforeach()
  install(EXPORT TumbleClientTargets NAMESPACE tumble:: DESTINATION ${tumble_cmake_dir})
  install(DIRECTORY proto/tumble/v1 DESTINATION ${CMAKE_INSTALL_DATADIR}/tumble/proto/tumble
    FILES_MATCHING PATTERN "*.proto")
endif()

configure_package_config_file(cmake/TumbleConfig.cmake.in
  ${PROJECT_BINARY_DIR}/cmake/TumbleConfig.cmake INSTALL_DESTINATION ${tumble_cmake_dir})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/cmake/TumbleConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/cmake/TumbleConfig.cmake
  ${PROJECT_BINARY_DIR}/cmake/TumbleConfigVersion.cmake DESTINATION ${tumble_cmake_dir})

# pkg-config: the libraries are static, so their own dependencies are listed as public ones. Paths
# are relative to the .pc file, since `cmake --install --prefix` chooses the prefix after configuring.
file(RELATIVE_PATH pc_to_include /p/${CMAKE_INSTALL_LIBDIR}/pkgconfig /p/${CMAKE_INSTALL_INCLUDEDIR})
configure_file(cmake/tumble.pc.in ${PROJECT_BINARY_DIR}/cmake/tumble.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/cmake/tumble.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
if(TUMBLE_INSTALLS_CLIENT)
  configure_file(cmake/tumble-client.pc.in ${PROJECT_BINARY_DIR}/cmake/tumble-client.pc @ONLY)
  install(FILES ${PROJECT_BINARY_DIR}/cmake/tumble-client.pc
    DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
endif()

foreach(program tumble tumble-server tumble-run tumble-viewer tumble-dds-echo)
  if(TARGET ${program})
    install(TARGETS ${program} RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  endif()
endforeach()
install(DIRECTORY shaders/ DESTINATION ${CMAKE_INSTALL_DATADIR}/tumble/shaders)
install(FILES scenes/default.json DESTINATION ${CMAKE_INSTALL_DATADIR}/tumble/scenes)
