#pragma once
// An allocator adaptor whose value-less construct() default-initialises: a vector's resize(n) then
// leaves new elements of a trivial T unwritten (no value-initialising pass over the block). For
// buffers whose every element is written afterwards, possibly by other threads, so that a fresh
// block's pages are first touched (faulted, zeroed by the kernel) where they are filled, not in a
// serial pass on the caller's thread. `Base` provides the memory (std::allocator<T>, a huge-page
// allocator, ...); everything else is Base's.
#include <memory>
#include <new>
#include <utility>

namespace cf {

template <class Base>
struct DefaultInitAllocator : Base {
  template <class U>
  struct rebind {
    using other = DefaultInitAllocator<typename std::allocator_traits<Base>::template rebind_alloc<U>>;
  };
  DefaultInitAllocator() = default;
  template <class B>
  DefaultInitAllocator(const DefaultInitAllocator<B>&) {}
  template <class U>
  void construct(U* p) noexcept {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... A>
  void construct(U* p, A&&... a) {
    ::new (static_cast<void*>(p)) U(std::forward<A>(a)...);
  }
};

}  // namespace cf
