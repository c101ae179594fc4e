"""ST[23] service user: file management requests and the decoding of their reports."""

from obsw.pus.messages import (
    SERVICE_FILE_MANAGEMENT,
    TC_FILE_ABORT_COPY,
    TC_FILE_ABORT_COPY_IN_PATH,
    TC_FILE_COPY,
    TC_FILE_CREATE,
    TC_FILE_CREATE_DIRECTORY,
    TC_FILE_DELETE,
    TC_FILE_DELETE_DIRECTORY,
    TC_FILE_DISABLE_COPY_STATUS_REPORTS,
    TC_FILE_ENABLE_COPY_STATUS_REPORTS,
    TC_FILE_FIND,
    TC_FILE_LOCK,
    TC_FILE_MOVE,
    TC_FILE_RENAME_DIRECTORY,
    TC_FILE_REPORT_ATTRIBUTES,
    TC_FILE_REPORT_REPOSITORY_SUMMARY,
    TC_FILE_RESUME_COPY,
    TC_FILE_RESUME_COPY_IN_PATH,
    TC_FILE_SUSPEND_COPY,
    TC_FILE_SUSPEND_COPY_IN_PATH,
    TC_FILE_UNLOCK,
    TM_FILE_ATTRIBUTE_REPORT,
    TM_FILE_COPY_STATUS_REPORT,
    TM_FILE_FOUND_REPORT,
    TM_FILE_REPOSITORY_SUMMARY_REPORT,
)
from obsw.pus.services.base import ServiceUser
from obsw.pus.services.s23_layouts import (
    ATTRIBUTES,
    COPY,
    COPY_STATUS,
    COPY_STATUS_NAMES,
    CREATE,
    DIRECTORY,
    FILE,
    FIND,
    FOUND,
    INTERVAL,
    OPERATIONS,
    RENAME_DIRECTORY,
    REPOSITORY,
    SUMMARY,
)


def _split(path):
    """'SAT:/data/a.bin' -> ('SAT:/data', 'a.bin')."""
    head, _, name = path.rpartition("/")
    if head.endswith(":"):
        head += "/"
    return head, name


class FileUser(ServiceUser):
    """The service 23 user. Files are named by full path (``SAT:/data/a.bin``)."""

    SERVICE = SERVICE_FILE_MANAGEMENT
    DECODERS = (
        (TM_FILE_ATTRIBUTE_REPORT, "decode_attributes"),
        (TM_FILE_FOUND_REPORT, "decode_found"),
        (TM_FILE_REPOSITORY_SUMMARY_REPORT, "decode_summary"),
        (TM_FILE_COPY_STATUS_REPORT, "decode_copy_status"),
    )

    def __init__(self):
        super().__init__()
        self.copy_status = {}  # operation ID -> last reported dict

    def _file(self, path):
        repo, name = _split(path)
        return FILE.pack({"repository": repo, "file": name})

    def create(self, apid, path, max_size=0):
        repo, name = _split(path)
        data = CREATE.pack({"repository": repo, "file": name, "max_size": max_size})
        return self.request(apid, TC_FILE_CREATE, data)

    def delete(self, apid, path):
        return self.request(apid, TC_FILE_DELETE, self._file(path))

    def attributes(self, apid, path):
        return self.request(
            apid, TC_FILE_REPORT_ATTRIBUTES, self._file(path), TM_FILE_ATTRIBUTE_REPORT
        )

    def lock(self, apid, path):
        return self.request(apid, TC_FILE_LOCK, self._file(path))

    def unlock(self, apid, path):
        return self.request(apid, TC_FILE_UNLOCK, self._file(path))

    def find(self, apid, repository, pattern):
        data = FIND.pack({"repository": repository, "pattern": pattern})
        return self.request(apid, TC_FILE_FIND, data, TM_FILE_FOUND_REPORT)

    def create_directory(self, apid, path):
        repo, name = _split(path)
        data = DIRECTORY.pack({"repository": repo, "directory": name})
        return self.request(apid, TC_FILE_CREATE_DIRECTORY, data)

    def delete_directory(self, apid, path):
        repo, name = _split(path)
        data = DIRECTORY.pack({"repository": repo, "directory": name})
        return self.request(apid, TC_FILE_DELETE_DIRECTORY, data)

    def rename_directory(self, apid, repository, old, new):
        data = RENAME_DIRECTORY.pack({"repository": repository, "old": old, "new": new})
        return self.request(apid, TC_FILE_RENAME_DIRECTORY, data)

    def summary(self, apid, repository):
        data = REPOSITORY.pack({"repository": repository})
        return self.request(
            apid, TC_FILE_REPORT_REPOSITORY_SUMMARY, data, TM_FILE_REPOSITORY_SUMMARY_REPORT
        )

    def _copy(self, apid, message_type, operation, source, target):
        sr, sf = _split(source)
        tr, tf = _split(target)
        data = COPY.pack(
            {
                "operation": operation,
                "source_repository": sr,
                "source_file": sf,
                "target_repository": tr,
                "target_file": tf,
            }
        )
        return self.request(apid, message_type, data)

    def copy(self, apid, operation, source, target):
        """Copy ``source`` to ``target`` (full paths) as operation ``operation``."""
        return self._copy(apid, TC_FILE_COPY, operation, source, target)

    def move(self, apid, operation, source, target):
        return self._copy(apid, TC_FILE_MOVE, operation, source, target)

    def _ops(self, apid, message_type, operations):
        return self.request(apid, message_type, OPERATIONS.pack({"operations": list(operations)}))

    def suspend(self, apid, operations):
        return self._ops(apid, TC_FILE_SUSPEND_COPY, operations)

    def resume(self, apid, operations):
        return self._ops(apid, TC_FILE_RESUME_COPY, operations)

    def abort(self, apid, operations):
        return self._ops(apid, TC_FILE_ABORT_COPY, operations)

    def _path(self, apid, message_type, repository):
        return self.request(apid, message_type, REPOSITORY.pack({"repository": repository}))

    def suspend_in_path(self, apid, repository):
        return self._path(apid, TC_FILE_SUSPEND_COPY_IN_PATH, repository)

    def resume_in_path(self, apid, repository):
        return self._path(apid, TC_FILE_RESUME_COPY_IN_PATH, repository)

    def abort_in_path(self, apid, repository):
        return self._path(apid, TC_FILE_ABORT_COPY_IN_PATH, repository)

    def enable_reports(self, apid, interval):
        data = INTERVAL.pack({"interval": interval})
        return self.request(apid, TC_FILE_ENABLE_COPY_STATUS_REPORTS, data)

    def disable_reports(self, apid):
        return self.request(apid, TC_FILE_DISABLE_COPY_STATUS_REPORTS)

    def decode_attributes(self, tm):
        return ATTRIBUTES.unpack(tm.data)

    def decode_found(self, tm):
        return FOUND.unpack(tm.data)

    def decode_summary(self, tm):
        out = SUMMARY.unpack(tm.data)
        out["files"] = [o["name"] for o in out["objects"] if o["type"] == 0]
        out["directories"] = [o["name"] for o in out["objects"] if o["type"] == 1]
        return out

    def decode_copy_status(self, tm):
        items = COPY_STATUS.unpack(tm.data)["operations"]
        for i in items:
            i["status_name"] = COPY_STATUS_NAMES.get(i["status"], "status %d" % i["status"])
            self.copy_status[i["operation"]] = i
        return {"operations": items}
