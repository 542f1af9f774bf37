// SPDX-License-Identifier: BSD-3-Clause
// Values that the layers above the model derive from it (the solver's KKT plans, simulate's
// welded model), built by those layers on first use and kept with the model: the model itself
// knows neither their types nor how they are built.
#pragma once

#include <memory>
#include <mutex>
#include <typeindex>
#include <utility>
#include <vector>

namespace armdyn::detail {

/// A thread-safe store of one value per type, filled on first request. Copying a model gives
/// the copy an empty store (its values are derived afresh from the copy, which may differ).
class DerivedCache {
 public:
  DerivedCache() = default;
  DerivedCache(const DerivedCache&) {}
  DerivedCache& operator=(const DerivedCache&) {
    clear();
    return *this;
  }

  /// The value of type T, made by build() (returning T) on the first request. A build may
  /// request other values of the same model (a recursive lock).
  template <class T, class Build>
  const T& get(Build&& build) const {
    std::lock_guard<std::recursive_mutex> lock(mutex_);
    for (const auto& [key, value] : entries_)
      if (key == std::type_index(typeid(T))) return *static_cast<const T*>(value.get());
    auto value = std::make_shared<const T>(std::forward<Build>(build)());
    const T& ref = *value;
    entries_.emplace_back(std::type_index(typeid(T)), std::move(value));
    return ref;
  }

  void clear() {
    std::lock_guard<std::recursive_mutex> lock(mutex_);
    entries_.clear();
  }

 private:
  mutable std::recursive_mutex mutex_;
  mutable std::vector<std::pair<std::type_index, std::shared_ptr<const void>>> entries_;
};

}  // namespace armdyn::detail
