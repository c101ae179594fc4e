metadata(
    version="0.1.0",
    description="PLUTO (ECSS-E-ST-70-32C): lexer, parser, interpreter, OBCP engine",
)

require("obsw-il", library="obsw")
require("obsw-pus", library="obsw")

package("obsw/pluto", base_path="../../../micropython")
