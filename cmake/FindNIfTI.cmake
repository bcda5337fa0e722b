# SPDX-License-Identifier: Apache-2.0
# Finds nifti_clib's NIfTI-2 reader from Debian 12's libnifti2-dev (it ships no CMake config).
# Defines the imported target NIfTI::nifti2 (reads NIfTI-1 and NIfTI-2, .nii and .nii.gz).
find_path(NIfTI_INCLUDE_DIR nifti/nifti2_io.h)
find_library(NIfTI_LIBRARY nifti2)
find_library(NIfTI_ZNZ_LIBRARY znz)
find_package(ZLIB)
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(NIfTI REQUIRED_VARS NIfTI_LIBRARY NIfTI_INCLUDE_DIR ZLIB_FOUND)
if(NIfTI_FOUND AND NOT TARGET NIfTI::nifti2)
  add_library(NIfTI::nifti2 UNKNOWN IMPORTED)
  set(_nifti_links ZLIB::ZLIB m)
  if(NIfTI_ZNZ_LIBRARY)
    list(PREPEND _nifti_links "${NIfTI_ZNZ_LIBRARY}")
  endif()
  set_target_properties(NIfTI::nifti2 PROPERTIES
    IMPORTED_LOCATION "${NIfTI_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${NIfTI_INCLUDE_DIR}/nifti"
    INTERFACE_LINK_LIBRARIES "${_nifti_links}")
endif()
mark_as_advanced(NIfTI_INCLUDE_DIR NIfTI_LIBRARY NIfTI_ZNZ_LIBRARY)
