// A fixed-size array whose memory nothing writes at construction: the large
// event buffers of readers, writers and the pipeline then cost page faults
// only for the pages a run touches (a 3-event file touches one of a 2 MB
// buffer), not for all of them up front. On a virtual machine whose page
// faults cost ~13 µs, zeroing the buffers of `evlife process` was a third of
// its start-up. Elements hold no value until written; callers read only what
// they wrote (every use passes counts with the span).
#pragma once

#include <cstddef>
#include <new>
#include <span>
#include <type_traits>
#include <utility>

namespace evlife::io {

template <class T>
class UninitializedArray {
  // operator new creates objects of implicit-lifetime types (C++20 [intro.object]).
  static_assert(std::is_trivially_copyable_v<T> && std::is_trivially_destructible_v<T>);

 public:
  UninitializedArray() noexcept = default;
  explicit UninitializedArray(std::size_t size)
      : data_(size == 0 ? nullptr : static_cast<T*>(::operator new(size * sizeof(T), std::align_val_t{alignof(T)}))),
        size_(size) {}
  UninitializedArray(UninitializedArray&& other) noexcept
      : data_(std::exchange(other.data_, nullptr)), size_(std::exchange(other.size_, 0)) {}
  UninitializedArray& operator=(UninitializedArray&& other) noexcept {
    std::swap(data_, other.data_);
    std::swap(size_, other.size_);
    return *this;
  }
  UninitializedArray(const UninitializedArray&) = delete;
  UninitializedArray& operator=(const UninitializedArray&) = delete;
  ~UninitializedArray() {
    if (data_ != nullptr) ::operator delete(data_, std::align_val_t{alignof(T)});
  }

  T* data() noexcept { return data_; }
  const T* data() const noexcept { return data_; }
  std::size_t size() const noexcept { return size_; }
  T& operator[](std::size_t i) noexcept { return data_[i]; }
  const T& operator[](std::size_t i) const noexcept { return data_[i]; }
  std::span<T> span() noexcept { return {data_, size_}; }

 private:
  T* data_ = nullptr;
  std::size_t size_ = 0;
};

}  // namespace evlife::io
