metadata(
    version="0.1.0",
    description="TC/TM space data links (232.0-B, 132.0-B), CLTU, FARM-1, SDLS, frame processor, "
    "TM coding and pacing, KISS",
)

require("obsw-base", library="obsw")

package(
    "obsw/frames",
    files=[
        "__init__.py",
        "aes.py",
        "asm.py",
        "bch.py",
        "clcw.py",
        "cltu.py",
        "contact.py",
        "conv.py",
        "dedup.py",
        "downlink.py",
        "errors.py",
        "farm.py",
        "gcm.py",
        "kiss.py",
        "processor.py",
        "randomizer.py",
        "rs.py",
        "sdls.py",
        "sdls_ep.py",
        "sdls_gcm.py",
        "sdls_keys.py",
        "sdls_mac.py",
        "tc.py",
        "tm.py",
        "tm_coding.py",
        "tm_mux.py",
        "tm_plan.py",
    ],
    base_path="../../../micropython",
)
