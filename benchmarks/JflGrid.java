import java.io.BufferedReader;
import java.io.InputStreamReader;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Paths;

import net.sourceforge.jFuzzyLogic.FIS;
import net.sourceforge.jFuzzyLogic.FunctionBlock;
import net.sourceforge.jFuzzyLogic.rule.Variable;

/**
 * MITOS's driver for a jFuzzyLogic jar (bench_conformance.py --jfuzzylogic JAR); not part of
 * jFuzzyLogic, it only calls its public API. It does what "java -jar JAR -e FILE.fcl IN_1 ... IN_N"
 * does (a fresh FIS for every point, the inputs of each function block in the alphabetical order
 * of their names), for many points in one JVM, and prints every output at full precision:
 *
 *   in FB.VAR ...                  the inputs, in the order each point gives them
 *   universe FB.VAR=MIN:MAX ...    each input's universe as jFuzzyLogic estimates it
 *   out FB.VAR=VALUE ...           a line per point read from stdin ("error MESSAGE" if it throws)
 *
 * or "load-error MESSAGE" alone when the file does not load.
 */
public class JflGrid {

	static String oneLine(Throwable t) {
		return t.toString().replace('\n', ' ').replace('\r', ' ');
	}

	public static void main(String[] args) throws Exception {
		String fcl = new String(Files.readAllBytes(Paths.get(args[0])), StandardCharsets.UTF_8);
		FIS first;
		try {
			first = FIS.createFromString(fcl, false);
			if (first == null) throw new RuntimeException("FIS.createFromString returned null");
		} catch (Throwable t) {
			System.out.println("load-error " + oneLine(t));
			return;
		}
		StringBuilder names = new StringBuilder("in");
		StringBuilder universes = new StringBuilder("universe");
		for (FunctionBlock fb : first)
			for (Variable var : fb.variablesSorted())
				if (var.isInput()) {
					names.append(" " + fb.getName() + "." + var.getName());
					var.estimateUniverse();
					universes.append(" " + fb.getName() + "." + var.getName() + "=" + var.getUniverseMin() + ":" + var.getUniverseMax());
				}
		System.out.println(names);
		System.out.println(universes);

		BufferedReader in = new BufferedReader(new InputStreamReader(System.in, StandardCharsets.UTF_8));
		String line;
		while ((line = in.readLine()) != null) {
			line = line.trim();
			if (line.isEmpty()) continue;
			String[] values = line.split("\\s+");
			try {
				FIS fis = FIS.createFromString(fcl, false);
				int k = 0;
				for (FunctionBlock fb : fis)
					for (Variable var : fb.variablesSorted())
						if (var.isInput()) var.setValue(Double.parseDouble(values[k++]));
				fis.evaluate();
				StringBuilder out = new StringBuilder("out");
				for (FunctionBlock fb : fis)
					for (Variable var : fb.variablesSorted())
						if (var.isOutput()) out.append(" " + fb.getName() + "." + var.getName() + "=" + var.getValue());
				System.out.println(out);
			} catch (Throwable t) {
				System.out.println("error " + oneLine(t));
			}
		}
	}
}
