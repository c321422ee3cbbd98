/* KDM_RUNTIME_API marks what the runtime library exports. It builds with hidden visibility, so nothing
 * else leaves a shared libkdm_runtime (a linker version script hides the C++ library's and cereal's
 * instantiations too). On Windows, a shared build defines KDM_RUNTIME_BUILDING while it builds and
 * KDM_RUNTIME_SHARED for its users (kdm::runtime's CMake target does both). */
#ifndef KDM_RUNTIME_EXPORT_H
#define KDM_RUNTIME_EXPORT_H

#if defined(_WIN32)
#if defined(KDM_RUNTIME_BUILDING) && defined(KDM_RUNTIME_SHARED)
#define KDM_RUNTIME_API __declspec(dllexport)
#elif defined(KDM_RUNTIME_SHARED)
#define KDM_RUNTIME_API __declspec(dllimport)
#else
#define KDM_RUNTIME_API
#endif
#elif defined(__GNUC__)
#define KDM_RUNTIME_API __attribute__((visibility("default")))
#else
#define KDM_RUNTIME_API
#endif

#endif /* KDM_RUNTIME_EXPORT_H */
