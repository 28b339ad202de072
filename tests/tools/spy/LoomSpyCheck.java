// Decodes every message of an LCM log the way lcm-spy does — by the 8-byte type fingerprint each
// message starts with, looked up among the classes of a types jar — and reports which channels it
// could decode. Exit 1 when a LOOM channel cannot be decoded, or when a required kind never appears.
// Usage: java -cp lcm.jar:loomlcm.jar:. LoomSpyCheck <loomlcm.jar> <log> KIND...
import java.io.DataInputStream;
import java.io.ByteArrayInputStream;
import java.util.*;
import java.util.jar.JarEntry;
import java.util.jar.JarFile;

public class LoomSpyCheck {
  public static void main(String[] args) throws Exception {
    Map<Long, Class<?>> byFingerprint = new HashMap<>();
    try (JarFile jar = new JarFile(args[0])) {
      for (Enumeration<JarEntry> e = jar.entries(); e.hasMoreElements();) {
        String name = e.nextElement().getName();
        if (!name.endsWith(".class") || name.contains("$")) continue;
        Class<?> c = Class.forName(name.replace('/', '.').replace(".class", ""));
        byFingerprint.put(c.getField("LCM_FINGERPRINT").getLong(null), c);
      }
    }
    lcm.logging.Log log = new lcm.logging.Log(args[1], "r");
    Map<String, String> decoded = new TreeMap<>();
    Map<String, Integer> counts = new TreeMap<>();
    int bad = 0;
    while (true) {
      lcm.logging.Log.Event ev;
      try { ev = log.readNext(); } catch (java.io.EOFException end) { break; }
      if (!ev.channel.startsWith("LOOM.")) continue;
      long fp = new DataInputStream(new ByteArrayInputStream(ev.data)).readLong();
      Class<?> c = byFingerprint.get(fp);
      if (c == null) {
        System.err.println("no type in the jar for " + ev.channel + " (fingerprint " + Long.toHexString(fp) + ")");
        bad++;
        continue;
      }
      c.getConstructor(byte[].class).newInstance((Object) ev.data);  // throws if it does not decode
      decoded.put(ev.channel, c.getSimpleName());
      counts.merge(ev.channel, 1, Integer::sum);
    }
    for (Map.Entry<String, String> e : decoded.entrySet()) {
      System.out.println(e.getKey() + " " + e.getValue() + " " + counts.get(e.getKey()));
    }
    for (int i = 2; i < args.length; i++) {
      final String kind = "." + args[i];
      if (decoded.keySet().stream().noneMatch(ch -> ch.endsWith(kind))) {
        System.err.println("no decoded message on a *" + kind + " channel");
        bad++;
      }
    }
    System.exit(bad == 0 ? 0 : 1);
  }
}
