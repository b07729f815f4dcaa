#!/usr/bin/env bash
# lcm-spy with the evldt message types: Debian's lcm-spy wrapper passes -Xincgc, which Java 17
# rejects, and knows nothing of our types; this runs the same class with our jar on the class path.
# Usage: deploy/lcm-spy.sh [--lcm-url=URL]   (needs a display; the jar comes with the build)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
jar=${EVLDT_LCMTYPES_JAR:-$root/build/release/lcmtypes/evldt_lcmtypes.jar}
[[ -f $jar ]] || { echo "lcm-spy.sh: $jar missing: build first (cmake --build build/release)" >&2; exit 1; }
exec java -Djava.net.preferIPv4Stack=true -Xmx256m \
  -cp "/usr/share/java/lcm.jar:/usr/share/java/jchart2d.jar:$jar" lcm.spy.Spy "$@"
