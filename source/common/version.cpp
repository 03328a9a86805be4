namespace cfdmpm {
const char* version() { return CFDMPM_VERSION; }
}  // namespace cfdmpm
