#include <msf/common/version.h>

const char* msf::versionString() { return MSF_VERSION_STRING; }
