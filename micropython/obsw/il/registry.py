"""Names to routes: local providers and links to other processes; no static port table.

A provider registers under its component name; users resolve the name on every call, so a
provider that is withdrawn and registered again (a restart) is found again. A ``resolver``
function, given by a transport, is asked for names that are not known locally and returns a
link to another process or None.
"""


class Registry:
    def __init__(self, resolver=None):
        self.resolver = resolver
        self._routes = {}

    def register(self, name, route):
        self._routes[name] = route

    def unregister(self, name, route=None):
        """Forget ``name``; with ``route``, only if the name still points there."""
        current = self._routes.get(name)
        if current is not None and (route is None or current is route):
            del self._routes[name]

    def forget_route(self, route):
        """Forget every name that points to ``route`` (a link that went down)."""
        for name in [n for n, r in self._routes.items() if r is route]:
            del self._routes[name]

    def resolve(self, name):
        route = self._routes.get(name)
        if route is None and self.resolver is not None:
            route = self.resolver(name)
            if route is not None:
                self._routes[name] = route
        return route

    def names(self):
        return sorted(self._routes)

    def __contains__(self, name):
        return name in self._routes
