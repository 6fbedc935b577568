"""Quality-of-service profiles of the wire contract (SPEC section 5)."""

from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

# ~/observations: reliable, keep-last 100 (SPEC) for publishers; the planner's subscription keeps all, so a burst
# larger than 100 waits in DDS (reliable back-pressure) instead of overwriting unread results
OBSERVATIONS_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=100, reliability=ReliabilityPolicy.RELIABLE,
                              durability=DurabilityPolicy.VOLATILE)
OBSERVATIONS_SUBSCRIPTION_QOS = QoSProfile(history=HistoryPolicy.KEEP_ALL, reliability=ReliabilityPolicy.RELIABLE,
                                           durability=DurabilityPolicy.VOLATILE)
# ~/proposals and ~/status: reliable, transient-local, depth 1 (a late joiner gets the latest message)
LATCHED_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1, reliability=ReliabilityPolicy.RELIABLE,
                         durability=DurabilityPolicy.TRANSIENT_LOCAL)
# ~/events: reliable, keep-last 100
EVENTS_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=100, reliability=ReliabilityPolicy.RELIABLE,
                        durability=DurabilityPolicy.VOLATILE)
# ~/recommend and ~/get_status: the default service QoS keeps only the last 10 requests, so concurrent callers beyond
# 10 would lose theirs while the optimizer works; the servers keep all of them
SERVICES_QOS = QoSProfile(history=HistoryPolicy.KEEP_ALL, reliability=ReliabilityPolicy.RELIABLE,
                          durability=DurabilityPolicy.VOLATILE)
# /diagnostics: as diagnostic_updater publishes it (reliable, keep-last 10)
DIAGNOSTICS_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=10, reliability=ReliabilityPolicy.RELIABLE,
                             durability=DurabilityPolicy.VOLATILE)
