#!/usr/bin/env python3
"""DDS Security material of the crane stack, made with the openssl CLI (docs/deployment.md, "Security").

  crane_security.py init  --out DIR --graph GRAPH.json [GRAPH.json ...] [--days N]
  crane_security.py issue --out DIR --identity NAME [--days N | --not-before T --not-after T]
  crane_security.py sign  --out DIR FILE.xml [...]

init writes into DIR (refuses a DIR that already holds a ca/):
  ca/ca.pem, ca/ca.key         the identity CA, also the permissions CA (EC P-256, self-signed)
  governance.xml, governance.p7s   one domain rule for every domain: unauthenticated participants
                               refused, join access control, discovery, liveliness and RTPS messages
                               encrypted, every topic with read/write access control and its data
                               encrypted; signed by the CA (S/MIME)
  <identity>/cert.pem, key.pem, permissions.xml, permissions.p7s   one per process and tool role
The identities: every participant name the topic graph shows (the stack's processes, each allowed
to publish exactly the topics it writes and to subscribe to those it reads), plus two tool roles:
  monitor   subscribes to every topic, publishes nothing (crane_topic, crane_web, a dashboard)
  operator  subscribes to every topic, publishes the operator's topics (goals, supervisor commands,
            operator speed; crane_move, crane_safety, crane_jog; the site's command,
            crane_site_status --out-of-service)
The graph is what DDS discovery reported of a running stack (endpoint_graph.sh, crane_topic list
--json): the permissions come from the nodes' own make_writer/make_reader calls, not from a list.

issue re-issues one identity's certificate with its existing key (rotation, or a test's expired
certificate); sign re-signs edited XML files with the CA (FILE.xml -> FILE.p7s).
Exit status 0 on success; 1 with a message naming the file or command that failed.
"""
import argparse
import datetime
import json
import os
import subprocess
import sys
import tempfile

DOMAIN_RANGE = (0, 230)  # the domains (Cyclone DDS 0.10 refuses a governance or permissions naming one above 230)
ORGANIZATION = "crane"
# Tool roles: the operator's own topics (what the operator tools write); the monitor writes none.
OPERATOR_TOPICS = ["rt/crane/planner/goal", "rt/crane/safety/command", "rt/crane/operator/speed", "rt/site/command"]
TOOL_ROLES = ("monitor", "operator")
# Participants of the graph that are tools watching the stack, not identities of their own.
GRAPH_TOOLS = ("crane_topic",)


def fail(message):
    print("crane_security: " + message, file=sys.stderr)
    sys.exit(1)


def openssl(*args, stdin=None):
    result = subprocess.run(["openssl", *args], input=stdin, capture_output=True, text=True)
    if result.returncode != 0:
        fail("openssl " + " ".join(args) + " failed: " + result.stderr.strip())
    return result.stdout


def subject(name):
    return "/O=%s/CN=%s" % (ORGANIZATION, name)


def subject_rfc2253(name):
    # What both vendors compare the permissions' subject_name with (RFC 2253 order: CN first).
    return "CN=%s,O=%s" % (name, ORGANIZATION)


def ca_config(out, not_before, not_after):
    """An `openssl ca` configuration: explicit validity dates, no database kept between calls."""
    work = tempfile.mkdtemp(prefix="crane_ca_", dir=out)
    open(os.path.join(work, "index.txt"), "w").close()
    with open(os.path.join(work, "serial"), "w") as f:
        f.write("%016x\n" % int.from_bytes(os.urandom(8), "big"))
    path = os.path.join(work, "ca.cnf")
    with open(path, "w") as f:
        f.write("""[ca]
default_ca = crane
[crane]
dir = {work}
database = {work}/index.txt
serial = {work}/serial
new_certs_dir = {work}
certificate = {out}/ca/ca.pem
private_key = {out}/ca/ca.key
default_md = sha256
policy = any
unique_subject = no
copy_extensions = none
x509_extensions = identity
[any]
organizationName = supplied
commonName = supplied
[identity]
basicConstraints = critical, CA:FALSE
keyUsage = critical, digitalSignature, keyAgreement
""".format(work=work, out=out))
    return work, path


def asn1_time(when):
    return when.strftime("%Y%m%d%H%M%SZ")


def make_ca(out, days):
    os.makedirs(os.path.join(out, "ca"))
    key = os.path.join(out, "ca", "ca.key")
    openssl("ecparam", "-name", "prime256v1", "-genkey", "-noout", "-out", key)
    os.chmod(key, 0o600)
    openssl("req", "-new", "-x509", "-key", key, "-out", os.path.join(out, "ca", "ca.pem"), "-days", str(days),
            "-subj", "/O=%s/CN=crane CA" % ORGANIZATION, "-addext", "basicConstraints=critical,CA:TRUE",
            "-addext", "keyUsage=critical,keyCertSign,cRLSign,digitalSignature")


def issue(out, name, not_before, not_after):
    folder = os.path.join(out, name)
    os.makedirs(folder, exist_ok=True)
    key = os.path.join(folder, "key.pem")
    if not os.path.exists(key):
        openssl("ecparam", "-name", "prime256v1", "-genkey", "-noout", "-out", key)
        os.chmod(key, 0o600)
    csr = os.path.join(folder, "cert.csr")
    openssl("req", "-new", "-key", key, "-out", csr, "-subj", subject(name))
    work, cnf = ca_config(out, not_before, not_after)
    try:
        openssl("ca", "-batch", "-config", cnf, "-in", csr, "-out", os.path.join(folder, "cert.pem"), "-notext",
                "-startdate", asn1_time(not_before), "-enddate", asn1_time(not_after))
    finally:
        for f in os.listdir(work):
            os.remove(os.path.join(work, f))
        os.rmdir(work)
        os.remove(csr)


def sign(out, xml):
    """FILE.xml -> FILE.p7s, S/MIME signed by the CA (what both vendors verify)."""
    if not os.path.isfile(xml):
        fail(xml + " does not exist")
    openssl("smime", "-sign", "-in", xml, "-text", "-out", xml[:-4] + ".p7s", "-signer",
            os.path.join(out, "ca", "ca.pem"), "-inkey", os.path.join(out, "ca", "ca.key"))


DDS_HEADER = ('<?xml version="1.0" encoding="UTF-8"?>\n'
              '<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" '
              'xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/{xsd}">\n')
DOMAINS = "<domains><id_range><min>%d</min><max>%d</max></id_range></domains>" % DOMAIN_RANGE


def governance_xml():
    return DDS_HEADER.format(xsd="omg_shared_ca_governance.xsd") + """  <domain_access_rules>
    <domain_rule>
      {domains}
      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>
      <enable_join_access_control>true</enable_join_access_control>
      <discovery_protection_kind>ENCRYPT</discovery_protection_kind>
      <liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>
      <rtps_protection_kind>ENCRYPT</rtps_protection_kind>
      <topic_access_rules>
        <topic_rule>
          <topic_expression>*</topic_expression>
          <enable_discovery_protection>true</enable_discovery_protection>
          <enable_liveliness_protection>true</enable_liveliness_protection>
          <enable_read_access_control>true</enable_read_access_control>
          <enable_write_access_control>true</enable_write_access_control>
          <metadata_protection_kind>NONE</metadata_protection_kind>
          <data_protection_kind>ENCRYPT</data_protection_kind>
        </topic_rule>
      </topic_access_rules>
    </domain_rule>
  </domain_access_rules>
</dds>
""".format(domains=DOMAINS)


def iso(when):
    return when.strftime("%Y-%m-%dT%H:%M:%S")


def permissions_xml(name, publish, subscribe, not_before, not_after):
    def topics(kind, names):
        if not names:
            return ""
        inner = "".join("<topic>%s</topic>" % t for t in names)
        return "        <%s><topics>%s</topics></%s>\n" % (kind, inner, kind)

    return DDS_HEADER.format(xsd="omg_shared_ca_permissions.xsd") + """  <permissions>
    <grant name="{name}">
      <subject_name>{subject}</subject_name>
      <validity><not_before>{nb}</not_before><not_after>{na}</not_after></validity>
      <allow_rule>
        {domains}
{publish}{subscribe}      </allow_rule>
      <default>DENY</default>
    </grant>
  </permissions>
</dds>
""".format(name=name, subject=subject_rfc2253(name), nb=iso(not_before), na=iso(not_after), domains=DOMAINS,
           publish=topics("publish", publish), subscribe=topics("subscribe", subscribe))


def read_graph(paths):
    """participant -> {"publish": set, "subscribe": set}, and every topic, from crane_topic list --json files."""
    roles, every_topic = {}, set()
    for path in paths:
        try:
            graph = json.load(open(path))
        except (OSError, ValueError) as error:
            fail("cannot read the topic graph %s: %s" % (path, error))
        for topic, entry in graph.items():
            every_topic.add(topic)
            for kind, key in (("writers", "publish"), ("readers", "subscribe")):
                for endpoint in entry.get(kind, []):
                    participant = endpoint["participant"]
                    if participant in GRAPH_TOOLS:
                        continue
                    roles.setdefault(participant, {"publish": set(), "subscribe": set()})[key].add(topic)
    if not roles:
        fail("the topic graph %s names no participant" % ", ".join(paths))
    return roles, every_topic


def write(path, text):
    with open(path, "w") as f:
        f.write(text)


def cmd_init(args):
    out = os.path.abspath(args.out)
    if os.path.exists(os.path.join(out, "ca")):
        fail(out + " already holds a CA (ca/): use 'issue' to rotate a certificate, or another --out")
    roles, every_topic = read_graph(args.graph)
    os.makedirs(out, exist_ok=True)
    now = datetime.datetime.now(datetime.timezone.utc).replace(microsecond=0)
    not_before = now - datetime.timedelta(hours=1)  # clocks of the other machines a little behind
    not_after = now + datetime.timedelta(days=args.days)
    make_ca(out, args.days + 1)
    write(os.path.join(out, "governance.xml"), governance_xml())
    sign(out, os.path.join(out, "governance.xml"))
    everything = sorted(every_topic | set(OPERATOR_TOPICS))
    roles["monitor"] = {"publish": set(), "subscribe": set(everything)}
    roles["operator"] = {"publish": set(OPERATOR_TOPICS), "subscribe": set(everything)}
    for name in sorted(roles):
        issue(out, name, not_before, not_after)
        xml = os.path.join(out, name, "permissions.xml")
        write(xml, permissions_xml(name, sorted(roles[name]["publish"]), sorted(roles[name]["subscribe"]),
                                   not_before, not_after))
        sign(out, xml)
        print("%-22s publishes %s" % (name, ", ".join(sorted(roles[name]["publish"])) or "nothing"))
    print("DDS Security material in %s: CA, governance, %d identities, valid until %s" %
          (out, len(roles), not_after.isoformat()))


def parse_time(text):
    when = datetime.datetime.fromisoformat(text)
    return when if when.tzinfo else when.replace(tzinfo=datetime.timezone.utc)


def cmd_issue(args):
    out = os.path.abspath(args.out)
    if not os.path.exists(os.path.join(out, "ca", "ca.key")):
        fail(out + " holds no CA (ca/ca.key): run 'init' first")
    now = datetime.datetime.now(datetime.timezone.utc).replace(microsecond=0)
    not_before = parse_time(args.not_before) if args.not_before else now - datetime.timedelta(hours=1)
    not_after = parse_time(args.not_after) if args.not_after else now + datetime.timedelta(days=args.days)
    if not_after <= not_before:
        fail("--not-after %s is not after --not-before %s" % (not_after, not_before))
    issue(out, args.identity, not_before, not_after)
    print("%s: certificate valid %s .. %s" % (os.path.join(out, args.identity, "cert.pem"), not_before, not_after))


def cmd_sign(args):
    out = os.path.abspath(args.out)
    for xml in args.files:
        if not xml.endswith(".xml"):
            fail(xml + " is not an .xml file")
        sign(out, xml)
        print(xml[:-4] + ".p7s signed")


def main():
    parser = argparse.ArgumentParser(description="DDS Security material of the crane stack (openssl CLI)")
    sub = parser.add_subparsers(dest="command", required=True)
    init = sub.add_parser("init", help="CA, governance, one identity and permissions per process and tool role")
    init.add_argument("--out", required=True)
    init.add_argument("--graph", nargs="+", required=True, help="crane_topic list --json of a running stack")
    init.add_argument("--days", type=int, default=365, help="validity of certificates and permissions [days]")
    issue_cmd = sub.add_parser("issue", help="re-issue one identity's certificate (same key)")
    issue_cmd.add_argument("--out", required=True)
    issue_cmd.add_argument("--identity", required=True)
    issue_cmd.add_argument("--days", type=int, default=365)
    issue_cmd.add_argument("--not-before", help="ISO 8601, UTC unless given")
    issue_cmd.add_argument("--not-after", help="ISO 8601, UTC unless given")
    sign_cmd = sub.add_parser("sign", help="re-sign edited XML with the CA (FILE.xml -> FILE.p7s)")
    sign_cmd.add_argument("--out", required=True)
    sign_cmd.add_argument("files", nargs="+")
    args = parser.parse_args()
    if getattr(args, "days", 1) <= 0:
        fail("--days %d must be > 0" % args.days)
    {"init": cmd_init, "issue": cmd_issue, "sign": cmd_sign}[args.command](args)


if __name__ == "__main__":
    main()
