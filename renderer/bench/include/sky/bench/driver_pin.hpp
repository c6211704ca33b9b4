// Keeps the Vulkan driver (ICD) loaded until the process exits. The Vulkan
// loader unloads lavapipe when the last instance is destroyed; the bench makes
// and destroys a renderer per case, and after an unload LeakSanitizer can no
// longer attribute the driver's own leaks to it (tests/lsan.supp suppresses
// them by library name), so a sanitized bench run would fail on Mesa's leaks.
#pragma once

namespace sky::bench {

// Takes one extra reference (dlopen RTLD_NOLOAD) on every Vulkan driver
// library now mapped (/proc/self/maps: ".../libvulkan_*.so"). Call after a
// renderer exists; idempotent in effect, never fails (a driver it cannot
// find is simply not pinned).
void keepVulkanDriversLoaded();

}  // namespace sky::bench
