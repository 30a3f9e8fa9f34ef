# install.cmake - what `cmake --install` puts under the prefix:
#   bin/paprsek (and bin/paprsek-mpi when MPI was found), include/paprsek.h, lib/libpaprsek.so.0.1.0 (+ .so.0, .so),
#   lib/libpaprsek.a, the library's modules where they were built (lib/paprsek/paprsek_openvdb.so,
#   lib/paprsek/paprsek_cuda.so, lib/paprsek/paprsek_draco.so: src/device/module.h), lib/pkgconfig/paprsek.pc and lib/cmake/paprsek/
#   (paprsekConfig.cmake, its version file, the exported targets
#   paprsek::paprsek and paprsek::paprsek_static).
include(CMakePackageConfigHelpers)

set(PK_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/paprsek)

install(TARGETS paprsek_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
# paprsek-mpi, when MPI was found: mpirun starts it by the same path on every machine
if(TARGET paprsek_mpi)
  install(TARGETS paprsek_mpi RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()
install(TARGETS paprsek_shared paprsek_static EXPORT paprsekTargets
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(FILES include/paprsek.h DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
# The modules, where the library looks for them (PK_MODULE_DIR, and
# LIBDIR/paprsek beside libpaprsek.so.0 wherever the prefix is).
foreach(module paprsek_openvdb paprsek_cuda paprsek_draco)
  if(TARGET ${module})
    install(TARGETS ${module} LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}/paprsek)
  endif()
endforeach()
# The denoiser's weights with their license, where the library looks for
# them (PK_DENOISE_WEIGHTS_DIR), when the build has fetched them.
install(DIRECTORY ${PK_WEIGHTS_DIR}/ DESTINATION ${CMAKE_INSTALL_DATADIR}/paprsek/weights OPTIONAL
        FILES_MATCHING PATTERN "*.tza" PATTERN "LICENSE.txt" PATTERN ".download" EXCLUDE)

install(EXPORT paprsekTargets NAMESPACE paprsek:: DESTINATION ${PK_CMAKE_DIR})
configure_package_config_file(cmake/paprsekConfig.cmake.in
  ${CMAKE_CURRENT_BINARY_DIR}/paprsekConfig.cmake INSTALL_DESTINATION ${PK_CMAKE_DIR})
# libpaprsek.so.0 keeps its ABI for every 0.x release.
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/paprsekConfigVersion.cmake
  COMPATIBILITY SameMajorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/paprsekConfig.cmake
  ${CMAKE_CURRENT_BINARY_DIR}/paprsekConfigVersion.cmake DESTINATION ${PK_CMAKE_DIR})

# paprsek.pc. Static linking (pkg-config --static) needs what the library
# links: libpng, cJSON, expat and zlib through their own .pc files where they have one,
# libjpeg, OpenEXRCore, the OpenMP flag, libm (and libdl, the thread library where the C library
# lacks them). Embree, oneDNN, CUDA and OpenVDB are not listed: they are loaded at run time.
set(PK_PC_REQUIRES_PRIVATE)
set(PK_PC_LIBS_PRIVATE ${OpenMP_C_FLAGS})
find_package(PkgConfig QUIET)
if(PKG_CONFIG_FOUND)
  pkg_check_modules(PK_PC_LIBPNG QUIET libpng)
  pkg_check_modules(PK_PC_LIBCJSON QUIET libcjson)
  pkg_check_modules(PK_PC_EXPAT QUIET expat)
  pkg_check_modules(PK_PC_ZLIB QUIET zlib)
endif()
if(PK_PC_LIBPNG_FOUND)
  list(APPEND PK_PC_REQUIRES_PRIVATE libpng)
else()
  foreach(lib ${PNG_LIBRARIES})
    get_filename_component(name ${lib} NAME_WE)
    string(REGEX REPLACE "^lib" "" name ${name})
    list(APPEND PK_PC_LIBS_PRIVATE -l${name})
  endforeach()
endif()
if(PK_PC_LIBCJSON_FOUND)
  list(APPEND PK_PC_REQUIRES_PRIVATE libcjson)
else()
  list(APPEND PK_PC_LIBS_PRIVATE -lcjson)
endif()
if(PK_PC_EXPAT_FOUND)
  list(APPEND PK_PC_REQUIRES_PRIVATE expat)
else()
  list(APPEND PK_PC_LIBS_PRIVATE -lexpat)
endif()
if(PK_PC_ZLIB_FOUND)
  list(APPEND PK_PC_REQUIRES_PRIVATE zlib)
else()
  list(APPEND PK_PC_LIBS_PRIVATE -lz)
endif()
# OpenEXR: the C library OpenEXRCore alone, by name. Its OpenEXR.pc would
# link the C++ libraries too (OpenEXR, Iex, IlmThread) and add Imath's
# headers, none of which the library uses.
list(APPEND PK_PC_LIBS_PRIVATE -ljpeg -l${PK_OPENEXR_LINK_NAME})
list(APPEND PK_PC_LIBS_PRIVATE -lm ${CMAKE_THREAD_LIBS_INIT})
foreach(lib ${PK_DL_LIBS})
  list(APPEND PK_PC_LIBS_PRIVATE -l${lib})
endforeach()
list(REMOVE_DUPLICATES PK_PC_LIBS_PRIVATE)
list(JOIN PK_PC_REQUIRES_PRIVATE ", " PK_PC_REQUIRES_PRIVATE)
list(JOIN PK_PC_LIBS_PRIVATE " " PK_PC_LIBS_PRIVATE)
if(IS_ABSOLUTE "${CMAKE_INSTALL_LIBDIR}")
  set(PK_PC_LIBDIR "${CMAKE_INSTALL_LIBDIR}")
else()
  set(PK_PC_LIBDIR "\${prefix}/${CMAKE_INSTALL_LIBDIR}")
endif()
if(IS_ABSOLUTE "${CMAKE_INSTALL_INCLUDEDIR}")
  set(PK_PC_INCLUDEDIR "${CMAKE_INSTALL_INCLUDEDIR}")
else()
  set(PK_PC_INCLUDEDIR "\${prefix}/${CMAKE_INSTALL_INCLUDEDIR}")
endif()
# The prefix is only known when installing (cmake --install --prefix P), so
# the file is written in two steps: everything else now, the prefix then.
set(PK_PC_PREFIX "@PK_PC_PREFIX@")
configure_file(cmake/paprsek.pc.in ${CMAKE_CURRENT_BINARY_DIR}/paprsek.pc.in @ONLY)
install(CODE "
  get_filename_component(PK_PC_PREFIX \"\${CMAKE_INSTALL_PREFIX}\" ABSOLUTE)
  configure_file(\"${CMAKE_CURRENT_BINARY_DIR}/paprsek.pc.in\" \"${CMAKE_CURRENT_BINARY_DIR}/paprsek.pc\" @ONLY)
")
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/paprsek.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
