// LeakSanitizer suppressions for the KUKA tests. OSMesa (Mesa 22.3) keeps a few small per-size
// framebuffer records and one global allocation alive until exit (about 1.5 KB, bounded by the
// number of distinct render sizes), which LeakSanitizer reports as leaks at exit. LeakSanitizer
// asks the program for default suppressions through this hook; builds without sanitizers never
// call it.
extern "C" const char* __lsan_default_suppressions();  // NOLINT(bugprone-reserved-identifier)

extern "C" const char* __lsan_default_suppressions() {  // NOLINT(bugprone-reserved-identifier)
  return "leak:libOSMesa.so\n";
}
