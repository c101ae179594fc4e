metadata(version="0.1.0", description="bit-level codec, CBOR, the context store")

require("obsw-base", library="obsw")

for _m in ("bits.py", "cbor.py", "store.py"):
    module("obsw/" + _m, base_path="../../../micropython")
