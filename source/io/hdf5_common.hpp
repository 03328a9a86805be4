#pragma once
// Internal to io/: what the HDF5 writer and reader share. An owning handle for HDF5 ids, checks
// that turn a failed call into an exception, and the file selection of a rank's owned boxes.
#include "io/output_layout.hpp"

#include <hdf5.h>

#include <cstddef>
#include <stdexcept>
#include <string>
#include <utility>

namespace cfdmpm::io_detail {

/// A root-group text attribute longer than this many bytes is stored by Hdf5Writer as the byte
/// dataset kTextDatasetGroup + name instead (an object header holds at most 64 KiB of
/// attributes); Hdf5Reader::attributeText reads either form.
inline constexpr std::size_t kLargestTextAttribute = 16384;
inline constexpr char kTextDatasetGroup[] = "/attributes/";

/// An HDF5 identifier closed by its own close function when it goes out of scope.
class H5Handle {
 public:
  H5Handle() = default;
  H5Handle(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  H5Handle(H5Handle&& other) noexcept { *this = std::move(other); }
  H5Handle& operator=(H5Handle&& other) noexcept
  {
    if (this != &other) {
      reset();
      id_ = std::exchange(other.id_, H5I_INVALID_HID);
      close_ = other.close_;
    }
    return *this;
  }
  H5Handle(const H5Handle&) = delete;
  H5Handle& operator=(const H5Handle&) = delete;
  ~H5Handle() { reset(); }

  hid_t get() const { return id_; }
  /// Closes now and reports whether the close succeeded.
  bool close()
  {
    herr_t status = 0;
    if (id_ >= 0) status = close_(id_);
    id_ = H5I_INVALID_HID;
    return status >= 0;
  }
  void reset() { close(); }
  /// Gives up ownership without closing.
  hid_t release() { return std::exchange(id_, H5I_INVALID_HID); }

 private:
  hid_t id_ = H5I_INVALID_HID;
  herr_t (*close_)(hid_t) = nullptr;
};

inline hid_t checked(hid_t id, const std::string& what)
{
  if (id < 0) throw std::runtime_error("HDF5: " + what + " failed");
  return id;
}

inline void checked(herr_t status, const std::string& what)
{
  if (status < 0) throw std::runtime_error("HDF5: " + what + " failed");
}

/// A file dataspace of the location's dataset shape (datasetDims) selecting the union of this
/// rank's owned boxes. HDF5 transfers such a selection in the file's row-major order, which is
/// ascending global index with x fastest: the order of an owned-entries buffer.
H5Handle ownedSelection(const OutputLayout& grid, int components);

}  // namespace cfdmpm::io_detail
