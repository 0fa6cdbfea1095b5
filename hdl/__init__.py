"""MyHDL blocks."""

from eyestereo.hdl.common.callinfo import install as _install_callinfo

# MyHDL's elaboration reads the whole call stack for every block; see eyestereo.hdl.common.callinfo.
_install_callinfo()
