metadata(version="0.1.0", description="the interaction layer: queues, nodes, providers, proxies")

require("obsw-base", library="obsw")
require("obsw-util", library="obsw")

package("obsw/il", base_path="../../../micropython")
