// mbed TLS for cryptolib and hashlib on the board images (boards/common/cryptolib.mk): AES with
// its tables in flash, the modes cryptolib offers, SHA-256. Nothing that allocates.
#ifndef OBSW_MBEDTLS_CONFIG_H
#define OBSW_MBEDTLS_CONFIG_H

#define MBEDTLS_AES_C
#define MBEDTLS_AES_ROM_TABLES
#define MBEDTLS_CIPHER_MODE_CBC
#define MBEDTLS_CIPHER_MODE_CTR
#define MBEDTLS_SHA256_C

#include "mbedtls/check_config.h"

#endif
