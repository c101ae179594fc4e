# cryptolib (AES: ECB, CBC, CTR) for both board images, on mbed TLS's AES and SHA-256, when
# tools/firmware.py has put mbed TLS's source into lib/mbedtls (the pinned archive leaves that
# submodule empty); without it the images build as before and obsw.compat falls back to AES in
# Python. Only the C define MICROPY_SSL_MBEDTLS is set, not the make variable: the TLS stack
# stays out, cryptolib and hashlib's SHA-256 use mbed TLS.
ifneq ($(wildcard $(TOP)/lib/mbedtls/library/aes.c),)
CFLAGS += -DMICROPY_PY_CRYPTOLIB=1 -DMICROPY_PY_CRYPTOLIB_CTR=1 -DMICROPY_SSL_MBEDTLS=1
CFLAGS += -I$(TOP)/lib/mbedtls/include -I$(BOARD_DIR)/../common
CFLAGS += -DMBEDTLS_CONFIG_FILE='"obsw_mbedtls_config.h"'
SRC_THIRDPARTY_C += $(addprefix lib/mbedtls/library/, aes.c sha256.c platform_util.c)
endif
